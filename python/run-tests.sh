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

# shellcheck source=scripts/python-suite.sh
source "$repo/scripts/python-suite.sh"
python_suite_setup "python tests" "$@"

cd "$here"
export CANFLEET_BIN_DIR="$build/bin"
export CANFLEET_DDS_DOMAIN="${CANFLEET_DDS_DOMAIN:-78}"  # node telemetry off other runs' DDS domain
exec "$python" -m pytest -p no:cacheprovider "--junitxml=$build/python-junit.xml" "${suite_args[@]}"
