#!/usr/bin/env bash
# The scale model of docs/farm.md, section 5: expected wall time of a sequence's ground truths
# on N nodes, by calculation from measured per-part CPU times (arguments, defaults: the
# figures measured for docs/farm.md). Prints one row per node count and split.
#   scripts/farm_model.sh [TILE_CPU_S="87.2 90.9 124.3 135.8"] [FIXED_S=9.4] [MERGE_S=4.9]
# TILE_CPU_S: CPU seconds of 1/16-row tiles of one frame (1 thread, all passes) sampled over
# the image; FIXED_S: a part's fixed cost (its 8 beam builds, the probe's, start-up: a 1-row
# part); MERGE_S: CPU of one frame's merge. Assumptions (stated in docs/farm.md): 16 one-thread
# tasks per 16-core node, each 1.18x slower than alone (CPU time at 16 threads over 2 threads on
# the lent 16-core Xeon, docs/benchmarks.md); batch groups split the passes (no build is
# repeated) and the probe stays with batch 0; parts run in waves of 16 N (but no faster than the
# longest part); scheduling latency and file-system time ignored.
set -eu
TILES=${1:-"87.2 90.9 124.3 135.8"}
FIXED=${2:-9.4}
MERGE=${3:-4.9}
FRAMES=${FRAMES:-300}
awk -v tiles="$TILES" -v F="$FIXED" -v M="$MERGE" -v frames="$FRAMES" 'BEGIN {
  n = split(tiles, t, " "); s = 0; for (i = 1; i <= n; i++) s += t[i]
  mean = s / n
  march = 16 * (mean - F)          # the march of a frame (main passes and probe): 16 tiles less their fixed costs
  frame = march + F                # one frame in one part: one fixed cost
  probe = 0.04 * march             # the probe: 1/25 of the pixels x 4 of 8 passes x 2 levels
  c = 1.18                         # contention of 16 tasks on 16 cores
  printf "per-frame CPU (1 core, 1 thread): %.0f s (march %.0f s of which probe %.0f s, fixed %.1f s)\n", frame, march, probe, F
  printf "%-6s %-16s %7s %6s %22s %10s %9s\n", "nodes", "split", "tasks", "waves", "mean/longest part (s)", "wall (h)", "CPU (h)"
  split("1 8 64", nodes, " "); split("1 4 8", bps, " ")
  for (k = 1; k <= 3; k++)
    for (b = 1; b <= 3; b++) {
      N = nodes[k]; S = 16 * N; B = bps[b]; tasks = frames * B
      waves = int((tasks + S - 1) / S)
      part = (march - probe) / B + probe + F                   # the longest: batch 0 (its passes, the probe)
      mean = (march + B * F) / B                               # the mean part
      wall = waves * mean; if (wall < part) wall = part        # parts in waves of S, at least the longest
      wall = wall * c + int((frames + S - 1) / S) * M          # then the merge array
      cpu = frames * (march + B * F) * c + frames * M
      printf "%-6d %-16s %7d %6d %15.0f / %4.0f %10.2f %9.1f\n", N, B " batch group" (B > 1 ? "s" : ""), tasks, waves, mean * c, part * c, wall / 3600, cpu / 3600
    }
}'
