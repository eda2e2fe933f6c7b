#!/usr/bin/env bash
# The python-canopen conformance suite (tests/conformance/README.md).
#
# Usage: tests/conformance/run.sh [BUILD_DIR] [PYTEST_ARGS...]
#   BUILD_DIR   CMake build folder whose bin/ has canfleet and canfleet-node (default: build)
#   PYTEST_ARGS passed on, e.g. -k quad-controller, -x, -v
#
# Creates/uses the project venv (scripts/python-env.sh: pinned python-can, canopen, pytest), then
# runs pytest. Exit codes: 0 every check passed; 1 a check failed; 2 usage or missing binaries;
# 77 the venv could not be made (no network on a fresh machine) - ctest reports that as skipped.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"

build="$repo/build"
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  build="$1"
  shift
fi
build="$(cd "$build" 2>/dev/null && pwd)" || { echo "conformance: no build folder '$build'" >&2; exit 2; }
for tool in canfleet canfleet-node; do
  if [ ! -x "$build/bin/$tool" ]; then
    echo "conformance: $build/bin/$tool is missing (build the project first)" >&2
    exit 2
  fi
done

if ! env_out="$("$repo/scripts/python-env.sh" 2>&1)"; then
  echo "conformance: scripts/python-env.sh could not provide python-canopen:" >&2
  echo "$env_out" >&2
  exit 77
fi
python="$(printf '%s\n' "$env_out" | tail -n 1)"

cd "$here"
export PYTHONDONTWRITEBYTECODE=1  # no __pycache__ in the source tree
echo "conformance: $("$python" -c 'import canopen, can; print(f"python-canopen {canopen.__version__}, python-can {can.__version__}")'), binaries from $build/bin"
export CANFLEET_BUILD_DIR="$build"
exec "$python" -m pytest "--build-dir=$build" "$@"
