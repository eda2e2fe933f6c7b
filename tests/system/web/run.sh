#!/usr/bin/env bash
# canfleet web's system tests (tests/system/web): the server against real fleets, and the page in
# Debian's headless chromium (skipped, saying so, where no chromium is installed).
#
# Usage: tests/system/web/run.sh [BUILD_DIR] [PYTEST_ARGS...]
# Screenshots (PNG) go to BUILD_DIR/web-screenshots: the run's artifacts. Exit codes as
# python/run-tests.sh (77: the venv could not be made).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../../.." && pwd)"
# shellcheck source=scripts/python-suite.sh
source "$repo/scripts/python-suite.sh"
python_suite_setup "web tests" "$@"
cd "$here"
export CANFLEET_WEB_SHOTS="$build/web-screenshots"
python_suite_pytest web 93
