#!/usr/bin/env bash
# The test command: installs what it needs, builds, and runs every test; a table of each step's
# wall time ends its output (also when a step fails).
#
#   scripts/test.sh                 every step below, in order (CI's .ci/run runs this)
#   scripts/test.sh STEP...         only those steps, e.g. `scripts/test.sh build ctest`
#   scripts/test.sh --sanitize      the same as `scripts/test.sh asan-build asan-tests fuzz-smoke`
#
# Steps:
#   deps         scripts/install-deps.sh (apt; nothing when all is there)
#   build        the tree with g++ (CMakePresets.json "default": build/, RelWithDebInfo -O2 -g1)
#   ctest        every test of build/: unit (simulated time), integration, system (real processes),
#                the scenario library, the python-canopen conformance suite, the VM SocketCAN test
#   docker       the container fleet on the real Docker engine, imaging the binaries of build/
#                (tests/docker/run.sh --prebuilt build; "SKIPPED: <reason>" without an engine)
#   asan-build   one clang build with ASan+UBSan and libFuzzer's coverage (preset "asan",
#                build-asan/): the unit and integration test binaries and the fuzz targets
#   asan-tests   the unit and integration tests under ASan+UBSan
#   fuzz-smoke   each libFuzzer target of build-asan/ for FUZZ_SECONDS (default 15)
#
# The tree is compiled twice, not three times: the sanitizer tests and the fuzz smoke share one
# clang build (clang compiles our -O0 ASan code in half the time g++ did). Long fuzzing runs keep
# their -O2 build (scripts/fuzz.sh --minutes N, preset "fuzz").
set -euo pipefail
cd "$(dirname "$0")/.."
# CI builds a fresh clone in a new folder each time: relative paths let ccache hit across clones.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true

all_steps=(deps build ctest docker asan-build asan-tests fuzz-smoke)
steps=()
for arg in "$@"; do
  case "$arg" in
    --sanitize) steps+=(asan-build asan-tests fuzz-smoke) ;;
    -h | --help)
      sed -n '2,26p' "$0"
      exit 0
      ;;
    *)
      case " ${all_steps[*]} " in
        *" $arg "*) steps+=("$arg") ;;
        *)
          echo "scripts/test.sh: no step '$arg' (steps: ${all_steps[*]}; or --sanitize)" >&2
          exit 2
          ;;
      esac
      ;;
  esac
done
[ ${#steps[@]} -eq 0 ] && steps=("${all_steps[@]}")
# Every step needs the packages: deps always runs first (a second or two when all is there).
case " ${steps[*]} " in *" deps "*) ;; *) steps=(deps "${steps[@]}") ;; esac

jobs=$(nproc)

step_deps() { scripts/install-deps.sh; }

step_build() {
  cmake --preset default >/dev/null
  cmake --build build -j "$jobs"
}

step_ctest() {
  ctest --test-dir build -j "$jobs" --output-on-failure
  # The scenario library's JUnit report (ctest's canfleet_scenario_library), for CI to keep.
  echo "scenario library JUnit report: build/scenarios-junit.xml"
}

# The container fleet on the real Docker engine (docker/compose.yaml): makes canfleet:dev of the
# binaries just built and tested in build/ (--prebuilt: no second compile inside the image), checks
# heartbeat loss on stop/kill/disconnect; prints "SKIPPED: <reason>" when no Docker engine answers.
step_docker() { tests/docker/run.sh --prebuilt build; }

step_asan_build() {
  cmake --preset asan >/dev/null
  # Only the binaries of the tests it runs (tests/CMakeLists.txt) and the fuzz targets.
  local fuzz_targets=()
  for f in fuzz/targets/*.cmake; do fuzz_targets+=("fuzz_$(basename "$f" .cmake)"); done
  cmake --build build-asan -j "$jobs" --target canfleet_unit_and_integration_tests "${fuzz_targets[@]}"
}

step_asan_tests() {
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan -L 'unit|integration' -j "$jobs" --output-on-failure
}

step_fuzz_smoke() { scripts/fuzz.sh --build build-asan "${FUZZ_SECONDS:-15}"; }

# The table of step times, printed at the end whatever happened.
names=()
times=()
results=()
report() {
  local total=0 i
  echo
  echo "== scripts/test.sh: step times (wall clock)"
  for i in "${!names[@]}"; do
    printf '   %-11s %6s  %s\n' "${names[$i]}" "$(clock "${times[$i]}")" "${results[$i]}"
    total=$((total + times[i]))
  done
  printf '   %-11s %6s\n' total "$(clock "$total")"
}
clock() { printf '%d:%02d' $(($1 / 60)) $(($1 % 60)); }
trap report EXIT

for step in "${steps[@]}"; do
  echo "== scripts/test.sh: $step"
  start=$SECONDS
  names+=("$step")
  times+=(0)
  results+=("running")
  status=0
  # In the background and waited for: a function called as `f || status=$?` would run with set -e
  # switched off (bash ignores errexit there), and a failing command inside a step must end it.
  "step_${step//-/_}" &
  wait $! || status=$?
  times[-1]=$((SECONDS - start))
  if [ "$status" -ne 0 ]; then
    results[-1]="FAILED (exit $status)"
    exit "$status"
  fi
  results[-1]="ok"
done
