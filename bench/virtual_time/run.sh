#!/usr/bin/env bash
# Benchmark of lock-step virtual time (issues 20 and 34): one simulated hour of a fleet under
# `canfleet test --time virtual`, as fast as the processes go. Prints the wall time, the factor
# (simulated / real seconds), the rounds and grants per simulated second, the verdict of the one
# expectation (no heartbeat lost), and beside it the in-process limit (canfleet-vt-limit: the same
# nodes in one process on one scheduler) and the ratio of the run to it. Figures, not a test:
# bench/virtual_time/README.md keeps them.
#
#   bench/virtual_time/run.sh [--capture] [--fleet hour|bus127] [--lookahead node|global] [BUILD_DIR]
#     --capture    also capture the buses and count their frames (writing a million lines of candump
#                  log costs the broker a few seconds: the timing is then not the benchmark's)
#     --fleet      hour (default): the ten-node fleet of hour.textproto; bus127: 127 Quads on one bus
#     --lookahead  node (default) or global: the rounds of one G for all (before issue 34)
set -euo pipefail
cd "$(dirname "$0")/../.."
capture=0
fleet=hour
lookahead=node
while [ $# -gt 0 ]; do
  case $1 in
    --capture) capture=1; shift ;;
    --fleet) fleet=$2; shift 2 ;;
    --lookahead) lookahead=$2; shift 2 ;;
    *) break ;;
  esac
done
build=${1:-build}
topology=bench/virtual_time/$fleet.textproto
[ -f "$topology" ] || { echo "no $topology"; exit 2; }
work=$(mktemp -d /tmp/canfleet-vt-bench-XXXXXX)
trap 'rm -rf "$work"' EXIT
start=$(date +%s.%N)
args=(test "$topology" --state-dir "$work/state" --lookahead "$lookahead")
[ "$capture" = 1 ] && args+=(--capture "$work/capture")
"$build/bin/canfleet" "${args[@]}" >"$work/out" 2>&1 || { cat "$work/out"; echo "the run failed"; exit 1; }
end=$(date +%s.%N)
grep -E "PASSED|FAILED|no-heartbeat-lost" "$work/out"
for log in "$work"/capture/*.log; do
  [ -e "$log" ] || continue
  echo "$(basename "$log" .log | sed "s/^$fleet-//"): $(wc -l <"$log") frames"
done
stats=$(grep -h "virtual time: .* rounds" "$work"/state/*/orchestrator.log | tail -1 | sed 's/.*virtual time: //')
echo "conductor: $stats"
wall=$(awk -v s="$start" -v e="$end" 'BEGIN { printf "%.1f", e - s }')
echo "$stats" | awk -v w="$wall" '{ printf "per simulated second: %.0f rounds, %.0f grants\n", $1 / 3600, $3 / 3600 }'
awk -v w="$wall" 'BEGIN { printf "wall %.1f s for 3600 simulated seconds: %.1fx real time\n", w, 3600 / w }'
limit=$("$build/bin/canfleet-vt-limit" "$topology" 3600 | tail -1)
echo "$limit"
echo "$limit" | awk -v w="$wall" '{ printf "ratio to the in-process limit: %.1f\n", w / $2 }'
