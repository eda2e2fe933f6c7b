#!/usr/bin/env bash
# The demo command: installs what it needs, builds, starts the demo fleet of topologies/ and shows
# it live until Ctrl-C, then stops every process.
#   scripts/demo.sh [TOPOLOGY]      default topologies/demo.textproto
#   scripts/demo.sh --docker [--keep]   the same fleet in containers (scripts/docker-demo.sh:
#                                   docker/compose.yaml, needs a Docker engine, no registry)
#
# What you see: `canfleet up` starts the orchestrator (broker, control API) and one process per
# node; its log (boot-ups, configuration, EMCYs, the scenario's faults and every expectation's
# verdict, "expect pass ...") goes to build/demo/orchestrator.log. The terminal shows `canfleet
# top`: every node by name with its NMT state, controller state, error register, heartbeat
# consumers and last EMCY as they publish it over DDS, the bus load, the scenario's cycle, clock,
# verdict counts and step, and its verdicts among the recent events; up/down and Enter open a
# node's simulated I/O and EMCY history, Esc goes back. The demo topology's scenario moves inputs,
# then injects and clears a heartbeat loss (40 s), an RPDO timeout (60 s) and a bus-off (80 s)
# in turn, each followed by expectations of the EMCY, NMT and output reactions; it runs again 10 s
# after it ended. `canfleet watch` in another terminal prints the events as lines, and `canfleet
# web` (started here, its URL printed) shows the fleet in a browser.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" = --docker ]; then
  shift
  exec scripts/docker-demo.sh "$@"
fi
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
topology=${1:-topologies/demo.textproto}

scripts/install-deps.sh
# The same configuration as scripts/test.sh (CMakePresets.json "default"): one build folder for both.
cmake --preset default >/dev/null
cmake --build build -j "$(nproc)" --target canfleet canfleet-node

bin=build/bin
mkdir -p build/demo
rm -f build/demo/ready
# Telemetry stays on this machine: every canfleet program takes the loopback configuration built
# in when given none, so `canfleet top` and `canfleet watch` in another terminal see this fleet.
"$bin/canfleet" up "$topology" --ready-file build/demo/ready >build/demo/orchestrator.log 2>&1 &
up=$!
web=""
stop() {
  if [ -n "$web" ]; then
    kill "$web" 2>/dev/null || true
    wait "$web" 2>/dev/null || true
  fi
  "$bin/canfleet" down >/dev/null 2>&1 || kill "$up" 2>/dev/null || true
  wait "$up" 2>/dev/null || true
  echo "demo stopped; the orchestrator's log is build/demo/orchestrator.log"
}
trap stop EXIT
trap 'exit 130' INT TERM

echo "starting the fleet of $topology (log: build/demo/orchestrator.log) ..."
for _ in $(seq 1 600); do
  grep -q "state ready" build/demo/ready 2>/dev/null && break
  kill -0 "$up" 2>/dev/null || { cat build/demo/orchestrator.log; exit 1; }
  sleep 0.1
done
"$bin/canfleet" status
echo
# The same fleet in a browser (web/README.md): port 8080, or any free one when 8080 is taken.
rm -f build/demo/web.ready
for listen in 127.0.0.1:8080 127.0.0.1:0; do
  "$bin/canfleet" web --listen "$listen" --ready-file build/demo/web.ready >build/demo/web.log 2>&1 &
  web=$!
  for _ in $(seq 1 50); do
    [ -f build/demo/web.ready ] && break
    kill -0 "$web" 2>/dev/null || break
    sleep 0.1
  done
  [ -f build/demo/web.ready ] && break
  web=""
done
[ -n "$web" ] && echo "in a browser: $(awk '/^url/{print $2}' build/demo/web.ready)  (canfleet web: overview, bus statistics, timeline, plots, fault controls)"
echo "live view (canfleet top; up/down and Enter: a node's I/O and EMCYs); Ctrl-C stops the demo"
echo "faults at 40 s, 60 s and 80 s after start; verdicts in top, canfleet watch --type verdict, or: grep expect build/demo/orchestrator.log"
sleep 2
"$bin/canfleet" top || true
