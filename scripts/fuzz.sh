#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz in build-fuzz/ (clang) and runs each on a copy of
# its seed corpus (docs/reliability.md, "Fuzzing").
#   scripts/fuzz.sh                 every target for 60 s (what CI runs when clang is present)
#   scripts/fuzz.sh 3600 fuzz_exr   one target for an hour
#   FUZZ_JOBS=2 scripts/fuzz.sh     targets run two at a time (default: 1)
# Findings (crash-*, leak-*, timeout-*, oom-*) are written to build-fuzz/findings/; exit 1 on any.
set -uo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fuzz_scene fuzz_exr fuzz_image fuzz_parts fuzz_manifest)
if ! command -v clang >/dev/null 2>&1 || ! command -v clang++ >/dev/null 2>&1; then
  echo "fuzz.sh: clang is not installed: skipped" >&2
  exit 0
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DGODRAYS_FUZZ=ON -DBUILD_TESTING=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >/dev/null || { echo "fuzz.sh: configure failed" >&2; exit 1; }
cmake --build build-fuzz -j "${JOBS:-2}" --target "${targets[@]}" || { echo "fuzz.sh: build failed" >&2; exit 1; }
mkdir -p build-fuzz/findings
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/fuzz/lsan.supp}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
run_one() {
  local t=$1 c=tests/fuzz/corpus/${1#fuzz_}
  local work=build-fuzz/corpus-${1#fuzz_}
  mkdir -p "$work"
  # fuzz_image: leak stacks through the uninstrumented OpenImageIO, for tests/fuzz/lsan.supp
  local asan=$ASAN_OPTIONS
  [ "$t" = fuzz_image ] && asan="$asan:fast_unwind_on_malloc=0"
  # -malloc_limit_mb: one allocation over 2 GB is a finding (the readers' size caps keep every
  # input below it); -rss_limit_mb is higher because the process's RSS creeps up over a long
  # fuzz_image run (2 GB after ~100 k executions under ASan's quarantine and OpenImageIO's
  # plugins, with 55 MB live), which is not one input's fault (the saved input ran alone at once)
  ASAN_OPTIONS=$asan build-fuzz/"$t" -max_total_time="$secs" -malloc_limit_mb=2048 -rss_limit_mb=8192 -timeout=30 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix=build-fuzz/findings/"$t"- "$work" "$c" >build-fuzz/"$t".log 2>&1
  local rc=$?
  local n
  n=$(sed -n 's/^stat::number_of_executed_units: *//p' build-fuzz/"$t".log | tail -1)
  echo "fuzz.sh: $t: ${n:-?} executions in $secs s, exit $rc (log: build-fuzz/$t.log)"
  return $rc
}
status=0
pids=()
for t in "${targets[@]}"; do
  run_one "$t" &
  pids+=($!)
  if [ ${#pids[@]} -ge "${FUZZ_JOBS:-1}" ]; then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
[ "$status" -eq 0 ] || { echo "fuzz.sh: FINDINGS (see build-fuzz/findings/)" >&2; tail -30 build-fuzz/fuzz_*.log >&2; }
exit $status
