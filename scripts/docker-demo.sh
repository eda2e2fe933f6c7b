#!/usr/bin/env bash
# The demo in containers (`scripts/demo.sh --docker`): builds the image (scripts/docker-build.sh:
# the Debian 12 base image is made locally with debootstrap when missing; BuildKit caches make a
# rebuild fast), starts docker/compose.yaml (the orchestrator and one container per node, wired as
# topologies/docker.textproto), waits until every node is operational, prints `canfleet status`,
# then shows `canfleet-top` from a container on the fleet's network (DDS) until you quit it
# (q or Ctrl-C). Then the fleet is removed (`compose down -v`).
#   scripts/docker-demo.sh [--keep]     --keep: leave the fleet running after canfleet-top
#
# The control API is published on 127.0.0.1:29700 (CANFLEET_CONTROL_PORT) and needs the fleet's
# token (docs/security.md): `scripts/docker-fleet.sh cli status` sends it, or by hand
# `CANFLEET_TOKEN_FILE=build-docker/secrets/canfleet-token build/bin/canfleet status`. In another terminal:
#   scripts/docker-fleet.sh compose stop quad-5      # quad-6, dio-20: EMCY 8130h, fault state
#   scripts/docker-fleet.sh compose start quad-5     # back, configured again; then:
#   scripts/docker-fleet.sh cli nmt start
set -euo pipefail
cd "$(dirname "$0")/.."
keep=0
[ "${1:-}" = --keep ] && keep=1

export CANFLEET_PROJECT="${CANFLEET_PROJECT:-canfleet}"
command -v docker >/dev/null || { echo "demo --docker: docker is not installed" >&2; exit 3; }
timeout 30 docker info >/dev/null 2>&1 || { echo "demo --docker: the Docker engine does not answer" >&2; exit 3; }

scripts/docker-build.sh
stop() {
  if [ "$keep" = 1 ]; then
    echo "fleet left running (project $CANFLEET_PROJECT): scripts/docker-fleet.sh down removes it"
  else
    scripts/docker-fleet.sh down >/dev/null 2>&1 || true
    echo "demo stopped; containers, network and volumes removed"
  fi
}
trap stop EXIT
trap 'exit 130' INT TERM

scripts/docker-fleet.sh up --timeout 240
scripts/docker-fleet.sh compose ps
scripts/docker-fleet.sh cli status
echo
echo "live view (canfleet-top in a container on network $(scripts/docker-fleet.sh network)); q or Ctrl-C stops the demo"
sleep 2
scripts/docker-fleet.sh top || true
