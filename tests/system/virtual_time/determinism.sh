#!/usr/bin/env bash
# Determinism of lock-step virtual time (issue 20, orchestrator/broker/README.md "Virtual time"):
# ten simulated minutes with heartbeat loss, RPDO timeout, a held bus-off and a probabilistic drop
# (determinism.textproto) run twice with the same seed, once on an idle machine and once with both
# cores kept busy; the candump capture of the bus (timestamps included) and every verdict line
# (EMCY codes and data, 1001h values, simulated times) must be byte-identical.
#
#   determinism.sh CANFLEET TOPOLOGY WORKDIR
set -euo pipefail
canfleet=$1
topology=$2
work=$3
rm -rf "$work"
mkdir -p "$work"

run() {
  local name=$1
  if ! "$canfleet" test "$topology" --state-dir "$work/$name-state" --capture "$work/$name" >"$work/$name.out" 2>&1; then
    cat "$work/$name.out"
    echo "FAIL: the $name run did not pass its expectations"
    exit 1
  fi
  # The achieved speed and the state folder differ from run to run by nature; nothing else may.
  grep -v -e ' real time$' -e '^state and logs' "$work/$name.out" >"$work/$name.verdicts"
  echo "$name run: $(grep ' real time$' "$work/$name.out" | sed 's/.*virtual time, //')"
}

run idle
busy=()
cleanup() { for pid in "${busy[@]}"; do kill "$pid" 2>/dev/null || true; done; }
trap cleanup EXIT
for _ in 1 2; do
  (while :; do :; done) &
  busy+=("$!")
done
run loaded
cleanup
busy=()

capture_idle="$work/idle/determinism-can0.log"
capture_loaded="$work/loaded/determinism-can0.log"
frames=$(wc -l <"$capture_idle")
echo "capture: $frames frames, $(grep -c ' can0 086#' "$capture_idle" || true) EMCYs of quad-6"
if [ "$frames" -lt 20000 ]; then
  echo "FAIL: the capture holds only $frames frames (ten minutes of this fleet are about 50 000)"
  exit 1
fi
grep -q ' can0 086#3081' "$capture_idle" || { echo "FAIL: no EMCY 8130h of quad-6 in the capture"; exit 1; }
grep -q ' can0 086#4081' "$capture_idle" || { echo "FAIL: no EMCY 8140h of quad-6 in the capture"; exit 1; }
if ! cmp "$capture_idle" "$capture_loaded"; then
  diff "$capture_idle" "$capture_loaded" | head -20
  echo "FAIL: the captures of the two runs differ"
  exit 1
fi
if ! cmp "$work/idle.verdicts" "$work/loaded.verdicts"; then
  diff "$work/idle.verdicts" "$work/loaded.verdicts"
  echo "FAIL: the verdicts of the two runs differ"
  exit 1
fi
echo "PASS: both runs byte-identical ($frames frames, $(wc -l <"$work/idle.verdicts") verdict lines)"
