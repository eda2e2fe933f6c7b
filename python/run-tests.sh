#!/usr/bin/env bash
# The canfleet Python package's tests (python/tests/): real fleets, python-can and python-canopen
# on the "canfleet" interface, the pytest plugin.
#
# Usage: python/run-tests.sh [BUILD_DIR] [PYTEST_ARGS...]
#   BUILD_DIR   CMake build folder whose bin/ has canfleet and canfleet-node (default: build)
#   PYTEST_ARGS passed on, e.g. -k can_bus, -x, -v
#
# Makes/uses the project venv with the package installed (scripts/python-env.sh), then runs pytest;
# JUnit in BUILD_DIR/python-junit.xml. Exit codes: 0 passed; 1 a test failed; 2 usage or missing
# binaries; 77 PyPI could not be reached for the venv (scripts/python-env.sh exit 75): ctest shows it skipped.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/.." && pwd)"

build="$repo/build"
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  build="$1"
  shift
fi
build="$(cd "$build" 2>/dev/null && pwd)" || { echo "python tests: no build folder '$build'" >&2; exit 2; }
for tool in canfleet canfleet-node; do
  if [ ! -x "$build/bin/$tool" ]; then
    echo "python tests: $build/bin/$tool is missing (build the project first)" >&2
    exit 2
  fi
done

env_status=0
env_out="$("$repo/scripts/python-env.sh" 2>&1)" || env_status=$?
if [ "$env_status" -ne 0 ]; then
  echo "python tests: scripts/python-env.sh could not provide the venv (exit $env_status):" >&2
  echo "$env_out" >&2
  # 75: PyPI unreachable, the machine's limit: skipped (77, ctest's SKIP_RETURN_CODE), said above.
  # Anything else (our package does not build) is a failure.
  [ "$env_status" -eq 75 ] && exit 77
  exit 1
fi
python="$(printf '%s\n' "$env_out" | tail -n 1)"

cd "$here"
export PYTHONDONTWRITEBYTECODE=1  # no __pycache__ in the source tree
export CANFLEET_BIN_DIR="$build/bin"
export CANFLEET_DDS_DOMAIN="${CANFLEET_DDS_DOMAIN:-78}"  # node telemetry off other runs' DDS domain
exec "$python" -m pytest -p no:cacheprovider "--junitxml=$build/python-junit.xml" "$@"
