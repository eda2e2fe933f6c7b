#!/usr/bin/env bash
# The python-canopen conformance suite (tests/conformance/README.md).
#
# Usage: tests/conformance/run.sh [BUILD_DIR] [PYTEST_ARGS...]
#   BUILD_DIR   CMake build folder whose bin/ has canfleet and canfleet-node (default: build)
#   PYTEST_ARGS passed on, e.g. -k quad-controller, -x, -v; --canfleet-time real runs the suite
#               in real time over socketcand (default: virtual time, python-canopen on the
#               canfleet interface)
#
# Creates/uses the project venv (scripts/python-env.sh: pinned python-can, canopen, pytest), then
# runs pytest. Exit codes: 0 every check passed; 1 a check failed; 2 usage or missing binaries;
# 77 PyPI could not be reached for the venv (scripts/python-env.sh exit 75) - ctest reports that as skipped.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"

# shellcheck source=scripts/python-suite.sh
source "$repo/scripts/python-suite.sh"
python_suite_setup "conformance" "$@"

cd "$here"
echo "conformance: $("$python" -c 'import canopen, can; print(f"python-canopen {canopen.__version__}, python-can {can.__version__}")'), binaries from $build/bin"
export CANFLEET_BUILD_DIR="$build"
# Virtual time unless the arguments say otherwise (--canfleet-time real: the wall-clock suite,
# python-canopen over socketcand).
time_mode=(--canfleet-time virtual)
for arg in "${suite_args[@]}"; do
  case "$arg" in --canfleet-time*) time_mode=() ;; esac
done
exec "$python" -m pytest "--build-dir=$build" "${time_mode[@]}" "${suite_args[@]}"
