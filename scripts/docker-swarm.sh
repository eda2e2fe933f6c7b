#!/usr/bin/env bash
# The canfleet fleet on Docker swarm, sharded by bus (also `scripts/docker-fleet.sh --swarm ...`).
# A shard file (topologies/swarm.shards) names the buses; each becomes an orchestrator service
# `<bus>-orchestrator` (broker, control API, socketcand) and a node service `<bus>-nodes` whose
# tasks take their node-ID from the task slot (docker/swarm/render.py; docker/README.md).
#
#   scripts/docker-swarm.sh up [SHARDS] [--timeout S] [--no-wait]
#                                  render SHARDS (default topologies/swarm.shards), create the overlay
#                                  network, deploy the stack, wait until every node is operational
#   scripts/docker-swarm.sh wait [--timeout S]   wait until every node of every bus is operational
#   scripts/docker-swarm.sh scale BUS N [--timeout S] [--no-wait]
#                                  docker service scale STACK_BUS-nodes=N (node-IDs 1..N), then wait
#   scripts/docker-swarm.sh status                one line per bus (nodes operational, frames/s, load)
#   scripts/docker-swarm.sh cli BUS ARGS...       the canfleet CLI against BUS's control API
#                                                 (e.g. `cli can0 status`, `cli can0 nmt start`)
#   scripts/docker-swarm.sh top [ARGS...]         canfleet-top in a container on the overlay network,
#   scripts/docker-swarm.sh watch [ARGS...]       canfleet-watch likewise (DDS: every bus, every node)
#   scripts/docker-swarm.sh web [--port P] [ARGS...]
#                                  canfleet web likewise, published on 127.0.0.1:P of this host
#                                  (default 8080): every bus's nodes, plots and timeline from DDS;
#                                  read-only (one web per fleet, one control API per bus: use
#                                  `canfleet web --control` of a bus for actions)
#   scripts/docker-swarm.sh ps                    the stack's tasks
#   scripts/docker-swarm.sh render [SHARDS] [--out DIR]   only write the stack file and topologies
#   scripts/docker-swarm.sh down                  remove the stack and its network; check that no
#                                                 service, container, network, config, secret or
#                                                 volume of it is left (exit 1 if one is)
#
# Environment: CANFLEET_STACK (stack name, default canfleet), CANFLEET_IMAGE (canfleet:dev; must be
# on every swarm node: --resolve-image never), CANFLEET_DDS_DOMAIN (0), CANFLEET_SWARM_SUBNET
# (10.213.0.0/16: tasks get addresses from its lower half, the monitor slots are at its top),
# CANFLEET_SWARM_MONITORS (4 monitor slots), CANFLEET_SWARM_BROKER_BASE / _CONTROL_BASE /
# _SOCKETCAND_BASE (host ports of the first bus: 29600, 29700, 29800; bus i adds i),
# CANFLEET_LOG_LEVEL (info). CANFLEET_CLI: a canfleet binary on this host used against the published
# control ports (default build/bin/canfleet when built; else `canfleet` inside the bus's
# orchestrator container when it runs here, else in a container on the overlay network);
# CANFLEET_SWARM_HOST: the address of the orchestrators' host for CANFLEET_CLI (127.0.0.1).
# CANFLEET_TOKEN_HOST_FILE: the fleet's token (default build-docker/secrets/canfleet-token, made
# with a random token when missing, shared with scripts/docker-fleet.sh): deployed as a Docker
# secret to every orchestrator and node, and sent by the CLI used here.
# Exit codes: 0 done, 1 failed or timed out, 2 usage, 3 no Docker engine or no swarm manager.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"

stack="${CANFLEET_STACK:-canfleet}"
image="${CANFLEET_IMAGE:-canfleet:dev}"
domain="${CANFLEET_DDS_DOMAIN:-0}"
subnet="${CANFLEET_SWARM_SUBNET:-10.213.0.0/16}"
monitors="${CANFLEET_SWARM_MONITORS:-4}"
MONITOR_DOCKER_ARGS=()
net="${stack}_fleet"

say() { echo "docker-swarm: $*"; }
die() { echo "docker-swarm: ERROR: $1" >&2; exit "${2:-1}"; }

# shellcheck source=scripts/fleet-token.sh
source "$repo/scripts/fleet-token.sh"

need_manager() {
  command -v docker >/dev/null || die "no 'docker' command" 3
  local state
  state=$(timeout 30 docker info --format '{{.Swarm.LocalNodeState}} {{.Swarm.ControlAvailable}}' 2>/dev/null) ||
    die "the Docker engine does not answer ('docker info' failed)" 3
  case "$state" in
    "active true") ;;
    "active false") die "this engine is a swarm worker: run this on a manager (docker node ls)" 3 ;;
    *) die "this engine is not in a swarm (state '${state%% *}'): docker swarm init --advertise-addr ADDRESS, or join one" 3 ;;
  esac
}

# ---- what the deployed stack says about itself (labels: any manager can run these commands) ----
service() { echo "${stack}_$1"; }
buses() {
  docker service ls --filter "label=com.docker.stack.namespace=$stack" --filter label=canfleet.role=orchestrator \
    --format '{{.Name}}' | sed "s/^${stack}_//; s/-orchestrator\$//" | sort
}
label() { docker service inspect -f "{{index .Spec.Labels \"$2\"}}" "$(service "$1")"; }
replicas() { docker service inspect -f '{{.Spec.Mode.Replicated.Replicas}}' "$(service "$1")"; }
# Nodes a bus should have: its node service's replicas plus its single-node services.
expected_nodes() {
  local bus=$1 n s
  n=$(replicas "$bus-nodes")
  for s in $(docker service ls --filter "label=com.docker.stack.namespace=$stack" --filter "label=canfleet.bus=$bus" \
    --filter label=canfleet.role=node --format '{{.Name}}'); do
    n=$((n + $(docker service inspect -f '{{.Spec.Mode.Replicated.Replicas}}' "$s")))
  done
  echo "$n"
}
net_label() { docker network inspect -f "{{index .Labels \"$1\"}}" "$net"; }

# The canfleet CLI against one bus's control API.
cli() {
  local bus=${1:?cli: which bus?} bin="${CANFLEET_CLI:-}" c
  shift
  if [ -z "$bin" ] && [ -x "$repo/build/bin/canfleet" ]; then bin="$repo/build/bin/canfleet"; fi
  if [ -n "$bin" ] && [ "$bin" != container ]; then
    CANFLEET_TOKEN_FILE="$CANFLEET_TOKEN_HOST_FILE" \
      "$bin" --control "tcp://${CANFLEET_SWARM_HOST:-127.0.0.1}:$(label "$bus-orchestrator" canfleet.control-port)" "$@"
    return
  fi
  c=$(docker ps -q --filter "label=com.docker.swarm.service.name=$(service "$bus-orchestrator")" | head -1)
  if [ -n "$c" ]; then
    docker exec "$c" canfleet --control tcp://127.0.0.1:29700 "$@"
  else
    docker run --rm --network "$net" -v "$CANFLEET_TOKEN_HOST_FILE:/run/secrets/canfleet_token:ro" \
      -e CANFLEET_TOKEN_FILE=/run/secrets/canfleet_token "$image" canfleet --control "tcp://$bus-orchestrator:29700" "$@"
  fi
}

# Reads `canfleet status --json` on stdin; exit 0 when EXPECTED nodes are attached and operational.
# Prints "BUS: N/EXPECTED operational, ..." (the topology names every slot; unattached ones are free slots).
bus_line() {
  python3 -c '
import json, sys
bus, expected = sys.argv[1], int(sys.argv[2])
try:
    s = json.load(sys.stdin)
except ValueError:
    print("%s: control API not answering" % bus)
    sys.exit(1)
nodes = s.get("nodes", [])
att = [n for n in nodes if n.get("attached")]
oper = [n for n in att if n.get("nmt_state") == "operational"]
other = [n["name"] + "(" + n.get("nmt_state", "?") + ")" for n in att if n.get("nmt_state") != "operational"]
b = (s.get("buses") or [{}])[0]
print("%s: %d/%d operational, %d attached, %d free slots; %.0f frames/s, load %.1f %%%s" % (
    bus, len(oper), expected, len(att), len(nodes) - len(att), b.get("frames_per_s", 0), b.get("load_percent", 0),
    "; not operational: " + " ".join(other[:8]) if other else ""))
sys.exit(0 if len(oper) == expected and len(att) == expected else 1)' "$@"
}

wait_operational() {
  local timeout=$1 start line all ok bus
  start=$(date +%s)
  while :; do
    ok=1
    all=""
    for bus in $(buses); do
      if ! line=$(cli "$bus" status --json 2>/dev/null | bus_line "$bus" "$(expected_nodes "$bus")"); then
        ok=0
        [ -n "$line" ] || line="$bus: control API not answering"
      fi
      all="$all${all:+ | }$line"
    done
    [ -n "$all" ] || { ok=0; all="no orchestrator service in stack $stack"; }
    if [ "$ok" = 1 ]; then
      say "every node operational after $(($(date +%s) - start)) s: $all"
      return 0
    fi
    if [ $(($(date +%s) - start)) -ge "$timeout" ]; then
      say "not every node operational after ${timeout} s: $all"
      docker stack ps --no-trunc --filter desired-state=running "$stack" 2>/dev/null | awk 'NR == 1 || $0 !~ /Running/' | head -20 || true
      return 1
    fi
    sleep 2
  done
}

render() { # SHARDS OUT
  ensure_fleet_token
  python3 "$repo/docker/swarm/render.py" "$1" --out "$2" --stack "$stack" --network "$net" --subnet "$subnet" \
    --monitors "$monitors" --domain "$domain" --image "$image" --log-level "${CANFLEET_LOG_LEVEL:-info}" \
    --broker-base "${CANFLEET_SWARM_BROKER_BASE:-29600}" --control-base "${CANFLEET_SWARM_CONTROL_BASE:-29700}" \
    --socketcand-base "${CANFLEET_SWARM_SOCKETCAND_BASE:-29800}" --token-file "$CANFLEET_TOKEN_HOST_FILE"
}

# The overlay network: attachable (monitors and CLI containers join it), with tasks' addresses from
# the lower half of the subnet so that the monitor slots at its top are never given to a task. The
# monitors' DDS configuration rides along as labels.
make_network() { # OUT
  local out=$1 ip_range slots uri
  ip_range=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["ip_range"])' "$out/shards.json")
  slots=$(python3 -c 'import json,sys; print(" ".join(json.load(open(sys.argv[1]))["monitor_slots"]))' "$out/shards.json")
  uri=$(cat "$out/monitor-uri.txt")
  if docker network inspect "$net" >/dev/null 2>&1; then
    [ "$(net_label canfleet.dds-uri)" = "$uri" ] ||
      die "network $net exists with another subnet or DDS setup: '$0 down' first (or another CANFLEET_STACK)"
    return 0
  fi
  docker network create --driver overlay --attachable --subnet "$subnet" --ip-range "$ip_range" \
    --label "canfleet.stack=$stack" --label "canfleet.monitor-slots=$slots" \
    --label "canfleet.dds-domain=$domain" --label "canfleet.dds-uri=$uri" "$net" >/dev/null
}

# canfleet-top / canfleet-watch in a container at a free monitor slot on the overlay network.
monitor() { # PROGRAM ARGS...
  local program=$1 slot i=0 err rc taken tty=()
  shift
  # MONITOR_DOCKER_ARGS: more `docker run` options (the web view's published port).
  docker network inspect "$net" >/dev/null 2>&1 || die "no network $net: is stack $stack deployed?"
  [ -t 0 ] && [ -t 1 ] && tty=(-it)
  # The addresses in use on the network, every host's (the verbose view comes from the network's
  # gossip): a slot that is taken would make the attachment fail only after a timeout.
  taken=" $(docker network inspect -v -f '{{range $s := .Services}}{{range $s.Tasks}}{{.EndpointIP}} {{end}}{{end}}' "$net" 2>/dev/null || true) "
  err=$(mktemp)
  for slot in $(net_label canfleet.monitor-slots); do
    i=$((i + 1))
    case "$taken" in *" $slot "*) continue ;; esac
    # The image's CANFLEET_DDS_CONFIG is emptied so that CYCLONEDDS_URI (the configuration itself) is used.
    docker run --rm "${tty[@]}" --name "$stack-monitor-$i" --network "$net" --ip "$slot" \
      --label "canfleet.stack=$stack" -e CANFLEET_DDS_CONFIG= "${MONITOR_DOCKER_ARGS[@]}" \
      -e "CYCLONEDDS_URI=$(net_label canfleet.dds-uri)" -e "CANFLEET_DDS_DOMAIN=$(net_label canfleet.dds-domain)" \
      "$image" "$program" "$@" 2>"$err" && rc=0 || rc=$?
    if [ "$rc" = 125 ] && grep -qiE 'in use|already|Conflict|attaching to network failed' "$err"; then
      continue # the slot was taken meanwhile (or the name is, on this host): try the next one
    fi
    cat "$err" >&2
    rm -f "$err"
    return "$rc"
  done
  rm -f "$err"
  die "every monitor slot of $net is taken ($(net_label canfleet.monitor-slots)); CANFLEET_SWARM_MONITORS sets how many"
}

down() {
  local start left
  start=$(date +%s)
  docker ps -aq --filter "label=canfleet.stack=$stack" | xargs -r docker rm -f >/dev/null
  if docker stack ls --format '{{.Name}}' | grep -qx "$stack"; then
    docker stack rm "$stack" >/dev/null || true
  fi
  # stack rm returns at once; the tasks' containers and the network endpoints go afterwards.
  while [ -n "$(docker ps -aq --filter "label=com.docker.stack.namespace=$stack")" ] ||
    [ -n "$(docker service ls -q --filter "label=com.docker.stack.namespace=$stack")" ]; do
    [ $(($(date +%s) - start)) -lt 90 ] || break
    sleep 1
  done
  while docker network inspect "$net" >/dev/null 2>&1; do
    docker network rm "$net" >/dev/null 2>&1 && break
    [ $(($(date +%s) - start)) -lt 120 ] || break
    sleep 1
  done
  left=$(
    docker service ls -q --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/service /'
    docker ps -aq --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/container /'
    docker ps -aq --filter "label=canfleet.stack=$stack" | sed 's/^/container /'
    docker network ls -q --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/network /'
    docker network ls -q --filter "label=canfleet.stack=$stack" | sed 's/^/network /'
    docker config ls -q --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/config /'
    docker secret ls -q --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/secret /'
    docker volume ls -q --filter "label=com.docker.stack.namespace=$stack" | sed 's/^/volume /'
  )
  if [ -n "$left" ]; then
    say "left behind by stack $stack:"
    echo "$left" | sort -u | sed 's/^/  /'
    return 1
  fi
  rm -rf "$repo/build-docker/swarm/$stack" # what `up` rendered
  say "stack $stack removed: no service, container, network, config, secret or volume left ($(($(date +%s) - start)) s)"
}

cmd="${1:-}"
[ $# -gt 0 ] && shift
timeout_s=300
case "$cmd" in
  up)
    shards="$repo/topologies/swarm.shards"
    wait=1
    while [ $# -gt 0 ]; do
      case "$1" in
        --timeout) timeout_s="${2:?--timeout needs seconds}"; shift ;;
        --no-wait) wait=0 ;;
        -*) die "up: unknown option '$1'" 2 ;;
        *) shards="$1" ;;
      esac
      shift
    done
    [ -f "$shards" ] || die "no shard file $shards" 2
    need_manager
    docker image inspect "$image" >/dev/null 2>&1 || "$repo/scripts/docker-build.sh" --tag "$image"
    out="$repo/build-docker/swarm/$stack"
    rm -rf "$out"
    mkdir -p "$out"
    render "$shards" "$out" || exit 2
    start=$(date +%s)
    make_network "$out"
    say "deploying stack $stack from $shards ($(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(", ".join("%s: %d nodes (max %d), control 127.0.0.1:%d, socketcand :%d" % (s["bus"], s["nodes"] + len(s["singles"]), s["max"], s["ports"]["control"], s["ports"]["socketcand"]) for s in d["shards"]))' "$out/shards.json"))"
    (cd "$out" && docker stack deploy --resolve-image never -c stack.yaml "$stack") 2>&1 |
      grep -vE '^(In a future release|Since --detach=false|Ignoring unsupported options)' || true
    [ "${PIPESTATUS[0]}" = 0 ] || die "docker stack deploy failed"
    if [ "$wait" = 1 ]; then
      wait_operational "$timeout_s" || exit 1
      say "deployed in $(($(date +%s) - start)) s"
    fi
    ;;
  wait | scale)
    need_manager
    if [ "$cmd" = scale ]; then
      bus="${1:?scale BUS N}"
      n="${2:?scale BUS N}"
      shift 2
      max=$(label "$bus-nodes" canfleet.max-slot) || die "no bus $bus in stack $stack" 2
      [ "$n" -ge 0 ] && [ "$n" -le "$max" ] ||
        die "$bus: its topology names node-IDs 1..$max; deploy again with a higher max= to scale to $n" 2
      docker service scale --detach "$(service "$bus-nodes")=$n" >/dev/null
      say "$(service "$bus-nodes") scaled to $n"
    fi
    wait=1
    while [ $# -gt 0 ]; do
      case "$1" in
        --timeout) timeout_s="${2:?--timeout needs seconds}"; shift ;;
        --no-wait) wait=0 ;;
        *) die "$cmd: unknown argument '$1'" 2 ;;
      esac
      shift
    done
    [ "$wait" = 0 ] || wait_operational "$timeout_s"
    ;;
  status)
    for bus in $(buses); do
      cli "$bus" status --json 2>/dev/null | bus_line "$bus" "$(expected_nodes "$bus")" || true
    done
    ;;
  cli) cli "$@" ;;
  top) monitor canfleet-top "$@" ;;
  watch) monitor canfleet-watch "$@" ;;
  web)
    port=8080
    if [ "${1:-}" = --port ]; then
      port="${2:?--port needs a port}"
      shift 2
    fi
    # Inside its container it listens on every address so that the published port reaches it; the
    # host publishes it on loopback only, and it takes no actions (no token to hand out here).
    MONITOR_DOCKER_ARGS=(-p "127.0.0.1:$port:8080")
    say "canfleet web on http://127.0.0.1:$port/ (read-only; Ctrl-C stops it)"
    monitor canfleet web --listen 0.0.0.0:8080 --read-only "$@"
    ;;
  ps) docker stack ps "$stack" "$@" ;;
  render)
    shards="$repo/topologies/swarm.shards"
    out="$repo/build-docker/swarm/$stack"
    while [ $# -gt 0 ]; do
      case "$1" in
        --out) out="${2:?}"; shift ;;
        *) shards="$1" ;;
      esac
      shift
    done
    mkdir -p "$out"
    render "$shards" "$out" && say "rendered into $out: $(cd "$out" && echo *)"
    ;;
  network) echo "$net" ;;
  down) need_manager; down ;;
  -h | --help | "") awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; [ -n "$cmd" ] || exit 2 ;;
  *) die "unknown command '$cmd' (see --help)" 2 ;;
esac
