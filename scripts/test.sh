#!/usr/bin/env bash
# Everything CI checks: install what is missing, build build/ with warnings as errors, build
# build-asan/ with AddressSanitizer + UndefinedBehaviorSanitizer and run the unit, cli and
# integration tests there (labels slow and heavy excluded: see tests/CMakeLists.txt), then run
# every test in build/. Exits non-zero
# on any failure.
#   ./scripts/test.sh          slow tests reduced in CI (CI=true), full locally
#   ./scripts/test.sh --full   slow tests full even in CI (same as GODRAYS_TEST_FULL=1)
#   ./scripts/test.sh --no-asan  skip the sanitizer phase
set -uo pipefail
cd "$(dirname "$0")/.."

asan=1
for a in "$@"; do
  case "$a" in
    --full) export GODRAYS_TEST_FULL=1 ;;
    --no-asan) asan=0 ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "test.sh: unknown argument '$a' (see --help)" >&2; exit 2 ;;
  esac
done
JOBS=${JOBS:-$(nproc 2>/dev/null || echo 2)}
# Slow tests run a reduced variant in CI unless asked for in full (tests read this variable).
if [ "${CI:-}" = "true" ] && [ "${GODRAYS_TEST_FULL:-0}" != "1" ]; then
  export GODRAYS_TEST_REDUCED=1
  echo "test.sh: CI: slow tests reduced (GODRAYS_TEST_REDUCED=1; --full to run them in full)"
fi

status=0
t_all=$SECONDS
t=$SECONDS
phase_times=()
phase() { # NAME: records the time since the previous phase
  phase_times+=("$(printf '%-28s %4ds' "$1" $((SECONDS - t)))")
  t=$SECONDS
}
summary() {
  echo
  echo "test.sh: elapsed time per phase"
  for p in "${phase_times[@]}"; do echo "  $p"; done
  echo "  $(printf '%-28s %4ds' total $((SECONDS - t_all)))"
}
fail() { # MESSAGE: a failure that stops everything after it
  echo "test.sh: FAILED: $1" >&2
  phase "$2"
  summary
  exit 1
}

./scripts/setup.sh || fail "setup" setup
phase setup

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DGODRAYS_WERROR=ON || fail "configure build/" "configure (Werror)"
cmake --build build -j "$JOBS" || fail "build build/ (warnings are errors)" "build (Werror)"
phase "configure + build (Werror)"

if [ "$asan" -eq 1 ]; then
  # Sanitizer build first, so that the closing ctest summary printed below is the full suite's.
  # LeakSanitizer stays on; UBSan stops at the first error (-fno-sanitize-recover).
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
  # -g1: line tables only (the reports' stack traces keep file:line); the full -g took 19 % more
  # of the compiler's time (report.c: 10.7 -> 8.6 s).
  dbg="-O2 -g1 -DNDEBUG"
  if cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGODRAYS_SANITIZE=ON \
       -DCMAKE_C_FLAGS_RELWITHDEBINFO="$dbg" -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$dbg" &&
     cmake --build build-asan -j "$JOBS"; then
    phase "configure + build (ASan+UBSan)"
    (cd build-asan && ctest --output-on-failure -j "$JOBS" -L 'unit|cli|integration' -LE 'slow|heavy') ||
      { status=1; echo "test.sh: FAILED: tests in build-asan/ (ASan+UBSan)" >&2; }
    phase "ctest build-asan/ (no slow/heavy)"
  else
    status=1
    echo "test.sh: FAILED: ASan+UBSan build" >&2
    phase "configure + build (ASan+UBSan)"
  fi
  unset ASAN_OPTIONS UBSAN_OPTIONS
fi

# The whole suite on the Werror build; its summary is ctest's closing one.
(cd build && ctest --output-on-failure -j "$JOBS") || { status=1; echo "test.sh: FAILED: tests in build/" >&2; }
phase "ctest build/ (all)"

# A short fuzz run of each libFuzzer target where clang is present (docs/reliability.md):
# 20 s each, two at a time (60 s before 2026-11-27: the CI budget went to new tests).
if command -v clang >/dev/null 2>&1; then
  FUZZ_JOBS=2 ./scripts/fuzz.sh 14 || { status=1; echo "test.sh: FAILED: fuzzing (build-fuzz/findings/)" >&2; }
  phase "fuzz (5 targets x 14 s)"
fi

summary
[ "$status" -eq 0 ] && echo "test.sh: all passed" || echo "test.sh: FAILED" >&2
exit "$status"
