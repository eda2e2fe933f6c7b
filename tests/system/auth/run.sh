#!/usr/bin/env bash
# The fleet's token, end to end (tests/system/auth): a real orchestrator listening beyond loopback,
# real node processes, the CLI, the Python client and python-can, each with no token, a wrong one
# and the right one; garbage and silent clients on the ports.
#
# Usage: tests/system/auth/run.sh [BUILD_DIR] [PYTEST_ARGS...]   (exit codes as python/run-tests.sh)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
# shellcheck source=scripts/python-suite.sh
source "$repo/scripts/python-suite.sh"
python_suite_setup "auth tests" "$@"
cd "$here"
python_suite_pytest auth 94
