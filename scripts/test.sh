#!/usr/bin/env bash
# The test command: installs what it needs, configures, builds and runs every test.
#   scripts/test.sh              full build + every test (unit, system, fuzz smoke)
#   scripts/test.sh --sanitize   ASan+UBSan build, unit and integration tests
set -euo pipefail
cd "$(dirname "$0")/.."
# CI builds a fresh clone in a new folder each time: relative paths let ccache hit across clones.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true

mode=full
[ "${1:-}" = "--sanitize" ] && mode=sanitize

scripts/install-deps.sh

jobs=$(nproc)
common=(-G Ninja -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)

if [ "$mode" = sanitize ]; then
  cmake -S . -B build-asan "${common[@]}" -DCMAKE_BUILD_TYPE=Debug -DCANFLEET_SANITIZE=ON >/dev/null
  # Only the binaries of the tests it runs (tests/CMakeLists.txt): 391 of 438 compiles, 41 of 67 links.
  cmake --build build-asan -j "$jobs" --target canfleet_unit_and_integration_tests
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-asan -L 'unit|integration' -j "$jobs" --output-on-failure
  exit 0
fi

cmake -S . -B build "${common[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build -j "$jobs" --output-on-failure
# The scenario library's JUnit report (ctest's canfleet_scenario_library), for CI to keep.
echo "scenario library JUnit report: build/scenarios-junit.xml"

# The container fleet on the real Docker engine (docker/compose.yaml): makes canfleet:dev of the
# binaries just built and tested in build/ (--prebuilt: no second compile inside the image), checks
# heartbeat loss on stop/kill/disconnect; prints "SKIPPED: <reason>" when no Docker engine answers.
tests/docker/run.sh --prebuilt build

scripts/fuzz.sh "${FUZZ_SECONDS:-15}"
