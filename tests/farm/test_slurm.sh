#!/bin/bash
# `godrays farm` on a real single-node Slurm cluster (label farm; docs/farm.md). As root, in a
# temporary folder: munged with a fresh key, slurmctld and slurmd (SlurmdUser root,
# proctrack/linuxproc, select/cons_tres, no cgroups, no systemd) from a generated slurm.conf
# naming this host, all stopped at the end by their pids. Then:
#  1. farm submits a 2-frame x 4-tile job array of a small scene, a merge job after it and a
#     final tune job after that, the parts and the merge requesting the memory the estimate
#     gives (--mem auto; the node has its RealMemory); one part's process is killed (SIGKILL)
#     mid-way;
#  2. all jobs finish: the killed part was retried (its log shows attempt 1 failed with 137 and
#     attempt 2 done), both frames' truths are in the cache, and each is byte for byte (every
#     channel, idiff with zero tolerance, and the batch statistics) a single local render;
#     tune ran on them from the cache (no ground-truth rendering: "ground truth 0.0 s");
#  3. farm --status says both cases are in the cache;
#  4. with one frame's truth and one of its parts removed, a resubmission's array is that one
#     part only; after it the frame is merged again, the same bytes;
#  5. farm --suite of a 2-case suite at 32x18 (2 batch groups each): each merged truth is byte
#     for byte `godrays reference` of its case, and the final run --suite finds both in the cache.
# Skips (exit 77) only when not root: the daemons need it. Missing packages are a failure
# (scripts/setup.sh installs slurm-wlm and munge).
set -u
[ "$(id -u)" -eq 0 ] || { echo "test_slurm: SKIP: needs root to start munged, slurmctld and slurmd"; exit 77; }
BIN=${GODRAYS_BINARY:?set by ctest}
SRC=${GODRAYS_SOURCE_DIR:?set by ctest}
for p in munged slurmctld slurmd sbatch squeue sinfo idiff oiiotool; do
  command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || { echo "test_slurm: FAIL: $p not found (scripts/setup.sh)"; exit 1; }
done
PATH=$PATH:/usr/sbin
T=$(mktemp -d /tmp/godrays-slurm.XXXXXX)
chmod 755 "$T"
fail=0
check() { # MESSAGE CONDITION...: records a failure
  local msg=$1; shift
  if "$@"; then echo "ok: $msg"; else echo "FAIL: $msg"; fail=1; fi
}
stop() {
  for f in "$T/slurmd.pid" "$T/slurmctld.pid" "$T/munge/munged.pid"; do
    [ -s "$f" ] && kill "$(cat "$f")" 2>/dev/null
  done
  sleep 1
  for f in "$T/slurmd.pid" "$T/slurmctld.pid" "$T/munge/munged.pid"; do
    [ -s "$f" ] && kill -9 "$(cat "$f")" 2>/dev/null
  done
  if [ $fail -ne 0 ]; then
    echo "--- logs (kept in $T) ---"; tail -n 20 "$T"/log/*.log "$T"/farm/logs/* 2>/dev/null
  else rm -rf "$T"; fi
}
trap stop EXIT

# ---- the cluster ----
mkdir -p "$T/munge" "$T/state" "$T/spool" "$T/log"
chmod 700 "$T/munge"
head -c 1024 /dev/urandom > "$T/munge/munge.key"
chmod 400 "$T/munge/munge.key"
munged --socket="$T/munge/munge.sock" --key-file="$T/munge/munge.key" --log-file="$T/log/munged.log" \
  --pid-file="$T/munge/munged.pid" --seed-file="$T/munge/seed" --force ||
  { echo "FAIL: munged did not start"; fail=1; exit 1; }
H=$(hostname -s)
PORT=$((20000 + ($$ % 5000) * 2))
CPUS=$(nproc)
# the node's memory (MiB, a little under what it has), so that jobs may request memory (--mem auto)
MEM=$(awk '/^MemTotal:/ {print int($2 / 1024) - 256}' /proc/meminfo)
cat > "$T/slurm.conf" <<EOF
ClusterName=godraystest
SlurmctldHost=$H(127.0.0.1)
AuthType=auth/munge
AuthInfo=socket=$T/munge/munge.sock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
StateSaveLocation=$T/state
SlurmdSpoolDir=$T/spool
SlurmctldPidFile=$T/slurmctld.pid
SlurmdPidFile=$T/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
NodeName=$H NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=test Nodes=$H Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$T/slurm.conf
slurmctld -f "$SLURM_CONF" || { echo "FAIL: slurmctld did not start"; fail=1; exit 1; }
slurmd -f "$SLURM_CONF" -N "$H" || { echo "FAIL: slurmd did not start"; fail=1; exit 1; }
for _ in $(seq 60); do
  [ "$(sinfo -h -o %t 2>/dev/null)" = "idle" ] && break
  sleep 0.5
done
check "single-node cluster up (sinfo: $(sinfo -h -o '%P %t %D' 2>&1))" test "$(sinfo -h -o %t)" = idle
[ $fail -eq 0 ] || exit 1

wait_idle() { # waits until the queue is empty (at most $1 s)
  for _ in $(seq $(($1 * 2))); do
    [ -z "$(squeue -h 2>/dev/null)" ] && return 0
    sleep 0.5
  done
  return 1
}

# ---- 1. submit; kill one part mid-way ----
export GODRAYS_CACHE=$T/cache
SCENE=$SRC/data/scenes/default.json
Q=(--size 96x54 --set reference.surface_res=64 --set reference.steps=48)
t0=$(date +%s.%N)
"$BIN" farm "$SCENE" "${Q[@]}" --frames 0:10:10 --tiles 4 --cpus 1 --partition test -o "$T/farm" --mem auto \
  --then tune --then-args "--params shafts.K --max-evals 4" > "$T/farm1.txt" 2>&1
check "farm submitted (exit 0)" test $? -eq 0
for s in parts.sh merge.sh; do check "$s requests memory (--mem auto)" grep -q '^#SBATCH --mem=[0-9]*M$' "$T/farm/$s"; done
cat "$T/farm1.txt"
killed=""
for _ in $(seq 400); do
  for f in "$T"/farm/logs/part-*.pid; do
    [ -s "$f" ] || continue
    pid=$(cat "$f")
    sleep 0.2 # mid-way: the render has started
    if kill -9 "$pid" 2>/dev/null; then killed=$(basename "$f" .pid); break 2; fi
  done
  sleep 0.05
done
check "a part's process was killed mid-way ($killed)" test -n "$killed"
wait_idle 400
t1=$(date +%s.%N)
check "queue drained" test -z "$(squeue -h)"
echo "farm run: $(awk "BEGIN { print $t1 - $t0 }") s wall for 8 parts + merge + tune on $CPUS cores (slurm)"

# ---- 2. results ----
if [ -n "$killed" ]; then
  check "$killed: attempt 1 failed (exit 137)" grep -q "attempt 1 failed (exit 137)" "$T/farm/logs/$killed.err"
  check "$killed: retried and done" grep -q "attempt 2" "$T/farm/logs/$killed.out"
  grep -h "" "$T/farm/logs/$killed.out" "$T/farm/logs/$killed.err"
fi
grep -h "done in" "$T"/farm/logs/part-*.out
cat "$T"/farm/logs/merge-*.out "$T"/farm/logs/merge-*.err 2>/dev/null
n=$(ls "$T"/cache/reference-*.exr 2>/dev/null | wc -l)
check "two merged truths in the cache ($n)" test "$n" -eq 2
for c in 0 1; do
  f=$((c * 10))
  "$BIN" reference "$T/farm/scene.json" --frame $f --fps 30 --threads 2 --quiet --no-preview -o "$T/local$c.exr"
  check "frame $f: local render" test -s "$T/local$c.exr"
  check "frame $f: merged truth = local render (idiff, zero tolerance)" \
    idiff -q -fail 0 -warn 0 "$T/local$c.exr" "$T/farm/truth/case-$c.exr"
  key=$(grep -o '[0-9a-f]\{16\}-[0-9a-f]\{16\}' <<< "$(sed -n "/CASE_KEYS/,/)/p" "$T/farm/parts.sh")" | sed -n "$((c + 1))p")
  check "frame $f: cached truth = local render" idiff -q -fail 0 -warn 0 "$T/local$c.exr" "$T/cache/reference-$key.exr"
  for k in image_mean rel_stderr_mean rel_stderr_p95 frac_pixels_stderr_le_1pct bias_surface_rel_est spp; do
    a=$(oiiotool --info -v "$T/local$c.exr" | grep "godrays:$k:")
    b=$(oiiotool --info -v "$T/farm/truth/case-$c.exr" | grep "godrays:$k:")
    check "frame $f: $k equal ($a)" test -n "$a" -a "$a" = "$b"
  done
done
cat "$T/farm/logs/final.out" 2>/dev/null | tail -n 3
check "final tune job used the cached truths" grep -q "ground truth 0.0 s" "$T/farm/logs/final.out"

# ---- 3. status ----
"$BIN" farm --status "$T/farm" > "$T/status.txt" 2>&1
cat "$T/status.txt"
check "status: 2 of 2 cases in the cache" grep -q "2 of 2 cases in the cache" "$T/status.txt"

# ---- 4. resubmission skips what is cached ----
key1=$(grep -o '[0-9a-f]\{16\}-[0-9a-f]\{16\}' <<< "$(sed -n "/CASE_KEYS/,/)/p" "$T/farm/parts.sh")" | sed -n 2p)
before=$(cat "$T"/farm/logs/part-[0-57]*.out | md5sum)
rm -f "$T/cache/reference-$key1.exr" "$T/cache/parts/$key1/tile-2-of-4.batches-0-of-1.part" "$T/farm/truth/case-1.exr"
"$BIN" farm "$SCENE" "${Q[@]}" --frames 0:10:10 --tiles 4 --cpus 1 --partition test -o "$T/farm" --then none \
  > "$T/farm2.txt" 2>&1
cat "$T/farm2.txt"
check "resubmission: only task 6 (frame 10, tile 2)" grep -q "array tasks to run: 6$" "$T/farm2.txt"
wait_idle 200
check "resubmission: frame 10 merged again, same bytes" \
  idiff -q -fail 0 -warn 0 "$T/local1.exr" "$T/cache/reference-$key1.exr"
check "resubmission: the other parts' logs are untouched (not re-run)" \
  test "$(cat "$T"/farm/logs/part-[0-57]*.out | md5sum)" = "$before"
check "resubmission: task 6 ran again" grep -q "done in" "$T/farm/logs/part-6.out"

# ---- 5. a view suite: farm --suite ----
# 2 cases at 32x18 (one turned and at another water time), 2 batch groups each: 4 part tasks, a
# 2-task merge array, and the final run --suite (one technique) that must find both truths in
# the cache. Each merged truth is compared with `godrays reference` of the scene file given the
# case's overrides by hand (not the farm's copy).
cat > "$T/suite.json" <<EOF
{"name": "tiny", "size": "32x18", "cases": [
 {"name": "up", "split": "train", "scene": "$SCENE"},
 {"name": "across", "split": "test", "scene": "$SCENE", "camera": {"yaw_deg": 120, "pitch_deg": 5}, "water": {"time_s": 0.5}}]}
EOF
SQ=(--set reference.surface_res=64 --set reference.steps=48)
T1=$("$BIN" techniques | awk 'NR == 1 { print $1 }')
t0=$(date +%s.%N)
"$BIN" farm --suite "$T/suite.json" "${SQ[@]}" --tiles 1 --batch-parts 2 --cpus 1 --partition test -o "$T/sfarm" \
  --then-args "--techniques $T1" > "$T/sfarm.txt" 2>&1
check "suite: farm submitted (exit 0)" test $? -eq 0
cat "$T/sfarm.txt"
check "suite: 4 part tasks (2 cases x 2 batch groups)" grep -q "array tasks to run: 0-3$" "$T/sfarm.txt"
wait_idle 300
echo "suite farm run: $(awk "BEGIN { print $(date +%s.%N) - $t0 }") s wall for 4 parts + 2 merges + run --suite"
grep -h "done in" "$T"/sfarm/logs/part-*.out
cat "$T"/sfarm/logs/merge-*.out "$T"/sfarm/logs/merge-*.err 2>/dev/null
CASE_SETS=("" "--set camera.yaw_deg=120 --set camera.pitch_deg=5 --set water.time_s=0.5")
for c in 0 1; do
  # shellcheck disable=SC2086 (the case's overrides are words)
  "$BIN" reference "$SCENE" --size 32x18 "${SQ[@]}" ${CASE_SETS[$c]} --threads 2 --quiet --no-preview -o "$T/slocal$c.exr"
  check "suite case $c: merged truth = reference of the case (idiff, zero tolerance)" \
    idiff -q -fail 0 -warn 0 "$T/slocal$c.exr" "$T/sfarm/truth/case-$c.exr"
  key=$(grep -o '[0-9a-f]\{16\}-[0-9a-f]\{16\}' <<< "$(sed -n "/CASE_KEYS/,/)/p" "$T/sfarm/parts.sh")" | sed -n "$((c + 1))p")
  check "suite case $c: cached truth = reference of the case" \
    idiff -q -fail 0 -warn 0 "$T/slocal$c.exr" "$T/cache/reference-$key.exr"
done
tail -n 4 "$T/sfarm/logs/final.out" "$T/sfarm/logs/final.err" 2>/dev/null
check "suite: the final run --suite found both truths in the cache" \
  test "$(grep -c "ground truth from the cache" "$T/sfarm/logs/final.err")" -eq 2
check "suite: run --suite wrote its leaderboard" test -s "$T/sfarm/run/metrics.json"

[ $fail -eq 0 ] && echo "all checks passed"
exit $fail
