#!/usr/bin/env bash
# Per-node lookahead changes how far node processes are granted, never what happens on the buses
# (issue 34, orchestrator/broker/README.md "Per-node lookahead"): the same files in virtual time,
# once with per-node lookahead and once with one G for all (the rounds before issue 34), give
# byte-identical captures and verdicts, and no causality error (something reaching a process before
# the time it was granted to).
#
#   lookahead_equivalence.sh CANFLEET WORKDIR FILE...
set -euo pipefail
canfleet=$1
work=$2
shift 2
rm -rf "$work"
mkdir -p "$work"

run() {
  local lookahead=$1
  shift
  if ! "$canfleet" test --time virtual --lookahead "$lookahead" "$@" --state-dir "$work/$lookahead-state" \
    --capture "$work/$lookahead" >"$work/$lookahead.out" 2>&1; then
    cat "$work/$lookahead.out"
    echo "FAIL: the run with --lookahead $lookahead did not pass its expectations"
    exit 1
  fi
  # The achieved speed and the state folder differ from run to run by nature; nothing else may.
  # Sorted: two reads of different nodes answered at one simulated instant are printed in the order
  # their answers were read (real time), with or without this change; their lines are the same.
  grep -v -e ' real time$' -e '^state and logs' "$work/$lookahead.out" | sort >"$work/$lookahead.verdicts"
}

run node "$@"
run global "$@"
captures=0
for log in "$work"/global/*.log; do
  other="$work/node/$(basename "$log")"
  if ! cmp "$log" "$other"; then
    diff "$log" "$other" | head -20
    echo "FAIL: $(basename "$log") differs between one G for all and per-node lookahead"
    exit 1
  fi
  captures=$((captures + 1))
done
[ "$captures" -gt 0 ] || { echo "FAIL: no capture was written"; exit 1; }
if ! cmp "$work/global.verdicts" "$work/node.verdicts"; then
  diff "$work/global.verdicts" "$work/node.verdicts"
  echo "FAIL: the verdicts differ"
  exit 1
fi
errors=$(grep -h "virtual time: .* rounds" "$work"/node-state/*/orchestrator.log | grep -cv " 0 causality errors" || true)
if [ "$errors" != 0 ]; then
  grep -h "causality" "$work"/node-state/*/orchestrator.log | head -5
  echo "FAIL: per-node lookahead reached a process before the time it was granted to"
  exit 1
fi
summary() { grep -h "virtual time: .* rounds" "$work/$1"-state/*/orchestrator.log | awk '{ r += $7; g += $9 } END { printf "%d rounds, %d grants", r, g }'; }
echo "PASS: $captures captures and $(wc -l <"$work/node.verdicts") verdict lines byte-identical; one G: $(summary global); per node: $(summary node)"
