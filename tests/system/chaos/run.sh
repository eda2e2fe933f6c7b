#!/usr/bin/env bash
# A few minutes of chaos against a real fleet (tests/system/chaos/chaos.py, issue 32); the hour is
# bench/chaos/run.sh. CANFLEET_CHAOS_S sets the duration (default 150 s), CANFLEET_CHAOS_SEED the seed.
#
# Usage: tests/system/chaos/run.sh [BUILD_DIR] [PYTEST_ARGS...]   (exit codes as python/run-tests.sh)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
# shellcheck source=scripts/python-suite.sh
source "$repo/scripts/python-suite.sh"
python_suite_setup "chaos test" "$@"
cd "$here"
python_suite_pytest chaos 95 -s
