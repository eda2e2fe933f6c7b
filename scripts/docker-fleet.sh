#!/usr/bin/env bash
# Runs the container fleet of docker/compose.yaml (topologies/docker.textproto) with whichever
# compose tool is here: `docker compose` (v2) when it works, else Debian's `docker-compose` (1.29).
#
#   scripts/docker-fleet.sh up [--build] [--timeout S]   compose up -d, then wait until every node is
#                                                        operational (--build: scripts/docker-build.sh first;
#                                                        without it the image is built only when missing)
#   scripts/docker-fleet.sh wait [--timeout S]           wait until every node is attached and operational
#   scripts/docker-fleet.sh cli ARGS...                  the canfleet CLI against the fleet's control API
#                                                        (e.g. `cli status`, `cli sdo read quad-6 0x1003 1 u32`)
#   scripts/docker-fleet.sh top [ARGS...]                canfleet-top in a container on the fleet's network (DDS)
#   scripts/docker-fleet.sh network                      prints the fleet's network name
#   scripts/docker-fleet.sh down                         compose down -v (containers, network, volumes)
#   scripts/docker-fleet.sh compose ARGS...              any compose command (ps, logs, stop quad-5, ...)
#   scripts/docker-fleet.sh --swarm COMMAND ...          the fleet as a swarm stack, sharded by bus:
#                                                        scripts/docker-swarm.sh (up, scale, status, top, down...)
#
# Environment: CANFLEET_PROJECT (compose project, default canfleet), CANFLEET_IMAGE (canfleet:dev),
# CANFLEET_CONTROL_PORT (29700), CANFLEET_BROKER_PORT (29600), CANFLEET_CAN0_PORT (29536),
# CANFLEET_CAN1_PORT (29537), CANFLEET_DDS_DOMAIN (0): host ports are published on 127.0.0.1 only.
# CANFLEET_CLI: the canfleet binary to use on the host (default build/bin/canfleet when built,
# else, or with CANFLEET_CLI=container, `canfleet` run inside the orchestrator's container).
# CANFLEET_TOKEN_HOST_FILE: the fleet's token (default build-docker/secrets/canfleet-token, made
# here with a random token when missing); the containers get it as the Docker secret canfleet_token
# and the host's CLI sends it (the control API listens beyond loopback inside its container).
# Exit codes: 0 done, 1 failed or timed out, 2 usage, 3 no compose tool or no Docker engine.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
if [ "${1:-}" = --swarm ]; then
  shift
  exec "$repo/scripts/docker-swarm.sh" "$@"
fi

export CANFLEET_PROJECT="${CANFLEET_PROJECT:-canfleet}"
export CANFLEET_IMAGE="${CANFLEET_IMAGE:-canfleet:dev}"
export CANFLEET_CONTROL_PORT="${CANFLEET_CONTROL_PORT:-29700}"
compose_file="$repo/docker/compose.yaml"

say() { echo "docker-fleet: $*"; }
die() { echo "docker-fleet: ERROR: $1" >&2; exit "${2:-1}"; }

# The compose tool, as an array: (docker compose) or (docker-compose).
compose_tool() {
  if docker compose version >/dev/null 2>&1; then
    compose=(docker compose)
  elif command -v docker-compose >/dev/null; then
    compose=(docker-compose)
  else
    die "neither 'docker compose' (v2 plugin) nor 'docker-compose' is installed" 3
  fi
}
compose_tool
dc() { "${compose[@]}" -f "$compose_file" -p "$CANFLEET_PROJECT" "$@"; }

# shellcheck source=scripts/fleet-token.sh
source "$repo/scripts/fleet-token.sh"
ensure_fleet_token

# The canfleet CLI talking to the fleet's control API.
cli() {
  local bin="${CANFLEET_CLI:-}"
  if [ -z "$bin" ] && [ -x "$repo/build/bin/canfleet" ]; then bin="$repo/build/bin/canfleet"; fi
  if [ -n "$bin" ] && [ "$bin" != container ]; then
    CANFLEET_TOKEN_FILE="$CANFLEET_TOKEN_HOST_FILE" "$bin" --control "tcp://127.0.0.1:$CANFLEET_CONTROL_PORT" "$@"
  else
    dc exec -T orchestrator canfleet --control tcp://127.0.0.1:29700 "$@"
  fi
}

network() {
  local id
  id=$(dc ps -q orchestrator)
  [ -n "$id" ] || die "the fleet ($CANFLEET_PROJECT) is not running"
  docker inspect -f '{{range $name, $net := .NetworkSettings.Networks}}{{$name}}{{"\n"}}{{end}}' "$id" | head -1
}

# Reads `canfleet status --json` on stdin; exit 0 when every node is attached and operational.
# Prints one line: "N/M operational; waiting for: ...".
all_operational() {
  python3 -c '
import json, sys
s = json.load(sys.stdin)
nodes = s.get("nodes", [])
bad = [n["name"] + "(" + ("attached" if n.get("attached") else "detached") + "," + n.get("nmt_state", "?") + ")"
       for n in nodes if not (n.get("attached") and n.get("nmt_state") == "operational")]
print("%d/%d operational%s" % (len(nodes) - len(bad), len(nodes), "; waiting for: " + " ".join(bad) if bad else ""))
sys.exit(1 if bad or not nodes else 0)'
}

wait_operational() {
  local timeout=$1 start line
  start=$(date +%s)
  while :; do
    if line=$(cli status --json 2>/dev/null | all_operational); then
      say "every node operational after $(($(date +%s) - start)) s: $line"
      return 0
    fi
    if [ $(($(date +%s) - start)) -ge "$timeout" ]; then
      say "not every node operational after ${timeout} s: ${line:-control API not answering}"
      dc ps || true
      dc logs --tail 30 orchestrator || true
      return 1
    fi
    sleep 1
  done
}

cmd="${1:-}"
[ $# -gt 0 ] && shift
timeout_s=180
case "$cmd" in
  up | wait)
    build=0
    while [ $# -gt 0 ]; do
      case "$1" in
        --build) build=1 ;;
        --timeout) timeout_s="${2:?--timeout needs seconds}"; shift ;;
        *) die "$cmd: unknown argument '$1'" 2 ;;
      esac
      shift
    done
    if [ "$cmd" = up ]; then
      timeout 30 docker info >/dev/null 2>&1 || die "the Docker engine does not answer ('docker info' failed)" 3
      if [ "$build" = 1 ] || ! docker image inspect "$CANFLEET_IMAGE" >/dev/null 2>&1; then
        "$repo/scripts/docker-build.sh" --tag "$CANFLEET_IMAGE"
      fi
      say "starting the fleet (project $CANFLEET_PROJECT, ${compose[*]}, control API 127.0.0.1:$CANFLEET_CONTROL_PORT)"
      dc up -d
    fi
    wait_operational "$timeout_s"
    ;;
  cli) cli "$@" ;;
  top)
    net=$(network)
    tty=()
    [ -t 0 ] && [ -t 1 ] && tty=(-it)
    docker run --rm "${tty[@]}" --network "$net" -e "CANFLEET_DDS_DOMAIN=${CANFLEET_DDS_DOMAIN:-0}" \
      "$CANFLEET_IMAGE" canfleet-top "$@"
    ;;
  network) network ;;
  down) dc down -v --remove-orphans --timeout 10 ;;
  compose) dc "$@" ;;
  -h | --help | "") awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; [ -n "$cmd" ] || exit 2 ;;
  *) die "unknown command '$cmd' (see --help)" 2 ;;
esac
