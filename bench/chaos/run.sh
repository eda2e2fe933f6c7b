#!/usr/bin/env bash
# An hour of chaos against a real fleet, real time (tests/system/chaos/chaos.py; issue 32), and its
# figures: kills, stores interrupted, values checked, the orchestrator's memory and descriptors
# per incarnation, the control API's latency p50/p99 (also under a babbling idiot).
#
#   bench/chaos/run.sh [--duration S] [--seed N] [--folder DIR]     (default an hour, seed 1)
# Builds nothing: run after `cmake --build build`; uses build/bin and the repository's .venv.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
"$repo/scripts/python-env.sh" >/dev/null
export CANFLEET_BIN_DIR="${CANFLEET_BIN_DIR:-$repo/build/bin}"
export CANFLEET_DDS_DOMAIN="${CANFLEET_DDS_DOMAIN:-96}"
cd "$repo/tests/system/chaos"
exec "$repo/.venv/bin/python" chaos.py "$@"
