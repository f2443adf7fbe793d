#!/bin/sh
# `godrays reference --phases` (issue 30: the render prints and records where its time goes;
# docs/reference.md 2.8): the printed table holds the figures of the EXR's own metadata
# (godrays:phase.NAME.wall_s, .cpu_s, .serial_s, read back by OpenImageIO's iinfo), its "all"
# row their sums, the serial fraction the metadata's, and Amdahl's speed-up from the render's
# threads to 16 computed from it; --phases with --bench is refused (exit 2).
. "$(dirname "$0")/lib.sh"
command -v iinfo >/dev/null || { echo "FAIL: iinfo not found (openimageio-tools)"; exit 1; }
cd "$dir" || exit 1
small_scene s.json 24 14
"$bin" reference s.json -o t.exr --no-preview -q --phases --threads 2 \
    --set reference.batches=2 --set reference.sun_samples=2 >phases.txt 2>err.txt
rc=$?
ck "reference --phases exits 0 ($rc: $(head -c 300 err.txt))" test "$rc" -eq 0
iinfo -v t.exr >meta.txt
ck "the table matches the metadata" python3 - phases.txt meta.txt <<'PY'
import re, sys
rows = {}
serial = amdahl = None
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) == 4 and f[0] != "phase":
        rows[f[0]] = [float(x) for x in f[1:]]
    m = re.match(r"serial fraction ([0-9.]+) % of the wall time on (\d+) threads; Amdahl from \d+ to 16 threads: ([0-9.]+)x", line)
    if m:
        serial, threads, amdahl = float(m.group(1)) / 100, int(m.group(2)), float(m.group(3))
meta = {}
for line in open(sys.argv[2]):
    m = re.match(r"\s*godrays:(\S+): (\S+)", line)
    if m:
        meta[m.group(1)] = m.group(2).strip('"')
names = ["beams", "grid", "pilot", "march", "probe", "stats", "other"]
assert sorted(rows) == sorted(names + ["all"]), rows.keys()
for n in names:
    for k, col in (("wall_s", 0), ("cpu_s", 1), ("serial_s", 2)):
        want = float(meta["phase.%s.%s" % (n, k)])
        assert abs(rows[n][col] - want) <= 5e-4 + 1e-6 * want, (n, k, rows[n][col], want)
for col in range(3):
    s = sum(rows[n][col] for n in names)
    assert abs(rows["all"][col] - s) <= 4e-3, (col, rows["all"][col], s)
assert rows["march"][1] > 0 and rows["beams"][1] > 0, rows
assert threads == int(meta["threads"]) == 2, (threads, meta["threads"])
sf = float(meta["serial_fraction"])
assert abs(serial - sf) <= 5e-5, (serial, sf)
assert abs(amdahl - 1 / (sf + (1 - sf) * 2 / 16)) <= 6e-3, (amdahl, sf)
PY
expect 2 "--phases and --bench" reference s.json --bench --phases
exit $fail
