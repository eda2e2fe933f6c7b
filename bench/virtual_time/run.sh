#!/usr/bin/env bash
# Benchmark of lock-step virtual time (issue 20 part 2): one simulated hour of the ten-node fleet of
# hour.textproto (the five variants twice, heartbeats every 500 ms with a consumer each, the default
# TPDOs) under `canfleet test --time virtual`, as fast as the processes go. Prints the wall time, the
# factor (simulated / real seconds), the frames on each bus and the false heartbeat losses (the one
# expectation: none). Figures, not a test: bench/virtual_time/README.md keeps them.
#
#   bench/virtual_time/run.sh [--capture] [BUILD_DIR]   (default: build)
#     --capture   also capture both buses and count their frames (writing a million lines of candump
#                 log costs the broker a few seconds: the timing is then not the benchmark's)
set -euo pipefail
cd "$(dirname "$0")/../.."
capture=0
if [ "${1:-}" = --capture ]; then
  capture=1
  shift
fi
build=${1:-build}
work=$(mktemp -d /tmp/canfleet-vt-bench-XXXXXX)
trap 'rm -rf "$work"' EXIT
start=$(date +%s.%N)
args=(test bench/virtual_time/hour.textproto --state-dir "$work/state")
[ "$capture" = 1 ] && args+=(--capture "$work/capture")
"$build/bin/canfleet" "${args[@]}" >"$work/out" 2>&1 || { cat "$work/out"; echo "the run failed"; exit 1; }
end=$(date +%s.%N)
grep -E "virtual time|PASSED|FAILED|no-heartbeat-lost" "$work/out"
for log in "$work"/capture/*.log; do
  [ -e "$log" ] || continue
  echo "$(basename "$log" .log | sed 's/^hour-//'): $(wc -l <"$log") frames"
done
awk -v s="$start" -v e="$end" 'BEGIN { w = e - s; printf "wall %.1f s for 3600 simulated seconds: %.1fx real time\n", w, 3600 / w }'
