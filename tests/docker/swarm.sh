#!/usr/bin/env bash
# System test of the fleet as a Docker swarm stack, sharded by bus (scripts/docker-swarm.sh,
# docker/swarm/render.py), on the real engine: a one-node swarm (made here with
# `docker swarm init --advertise-addr 127.0.0.1` when the engine is in none, and left again at the
# end; an existing swarm is used as it is, from a manager).
#
#   tests/docker/swarm.sh [--no-build] [--keep]
#     --no-build   use the existing image $CANFLEET_IMAGE (tests/docker/run.sh has just built it);
#                  without it the image is built only when missing
#     --keep       leave the stack (and the swarm) up at the end
#
# Prints "SKIPPED: <reason>" and exits 0 when no engine answers or it cannot run a swarm (cannot
# init one, is a worker, cannot create an overlay network). Exit 1 on a failed check ("FAIL: ..."),
# 2 on bad arguments. Time-boxed: CANFLEET_SWARM_TEST_BUDGET seconds for the whole run (default 420;
# about 2-3 minutes on an idle 2-core machine).
#
# What it checks:
#  1. two buses, 10 nodes each (can0: Quad controllers at 250 kbit/s, can1: generic CiA 401 nodes
#     from canfleet-dio16.eds at 500 kbit/s), one orchestrator service per bus: every node attached
#     and operational through each bus's control API (published in host mode); the orchestrator
#     configured the nodes whose node-ID and name come from their task slot (1016h, 1017h read back)
#  2. socketcand of can0 on its published port (hi, open, a frame in raw mode); can1's control API port
#  2b. the fleet's token: a Docker secret of the orchestrator and node services; a CLI without it
#     is refused by the published control API
#  3. `docker service scale` of can0's node service to 20: 30 nodes operational
#  4. DDS across the overlay with unicast discovery only: canfleet-top --once in a container at a
#     monitor slot on the overlay network shows all 30 nodes of both buses operational
#  4b. canfleet web at a monitor slot (`scripts/docker-swarm.sh web`), published on loopback: its
#     /api/state shows the 30 nodes of both buses operational, the page is served, actions are refused
#  5. `docker kill` of node 3's task on can0: its consumer can0-node-4 reports the heartbeat loss
#     (EMCY 8130h, control API and canfleet-watch on the overlay) and goes pre-operational; swarm
#     replaces the task (same slot, so same node-ID and name), the orchestrator configures it again
#     (1016h/1017h read back), node 4 sends EMCY 0000h (seen by canfleet-watch); after NMT start all
#     30 operational, and canfleet-top (a new monitor) sees the new task's node too
#  6. the figures of this run: deploy and scale times, RSS per node and per orchestrator, frames/s
#     and load per bus
#  7. `scripts/docker-swarm.sh down`: no service, container, network, config, secret or volume left
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$repo"

build=1
keep=0
for arg in "$@"; do
  case "$arg" in
    --no-build) build=0 ;;
    --keep) keep=1 ;;
    -h | --help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; exit 0 ;;
    *) echo "tests/docker/swarm.sh: unknown argument '$arg'" >&2; exit 2 ;;
  esac
done

t0=$(date +%s)
budget="${CANFLEET_SWARM_TEST_BUDGET:-420}"
log() { echo "swarm-test: $*"; }
checks=()
figures=()
pass() { checks+=("$*"); log "ok: $*"; }
fail() {
  echo "swarm-test: FAIL: $*" >&2
  exit 1
}
skipped=0
skip() {
  echo "swarm-test: SKIPPED: $*"
  skipped=1
  exit 0
}
elapsed() { echo "$(($(date +%s) - $1)) s"; }
left() { echo $((budget - ($(date +%s) - t0))); }
# A wait bounded by LIMIT and by what is left of the budget.
bound() { local l; l=$(left); [ "$1" -lt "$l" ] && echo "$1" || echo "$((l > 5 ? l : 5))"; }

# ---- can this engine run a swarm? ------------------------------------------------------------------
command -v docker >/dev/null || skip "no 'docker' command on this machine (the swarm test needs a Docker engine)"
timeout 30 docker info >/dev/null 2>&1 || skip "the Docker engine does not answer ('docker info' failed or timed out)"
command -v python3 >/dev/null || fail "python3 is needed (render.py, canfleet status --json)"
made_swarm=0
had_gwbridge=0
docker network inspect docker_gwbridge >/dev/null 2>&1 && had_gwbridge=1
state=$(docker info --format '{{.Swarm.LocalNodeState}}')
case "$state" in
  inactive)
    if ! out=$(timeout 60 docker swarm init --advertise-addr 127.0.0.1 2>&1); then
      skip "this engine cannot start a swarm: docker swarm init --advertise-addr 127.0.0.1: $(echo "$out" | tail -1)"
    fi
    made_swarm=1
    log "made a one-node swarm (docker swarm init --advertise-addr 127.0.0.1); it is left at the end"
    ;;
  active)
    [ "$(docker info --format '{{.Swarm.ControlAvailable}}')" = true ] ||
      skip "this engine is a worker of a swarm: stacks are deployed from a manager"
    log "using the swarm this engine is already in (not left at the end)"
    ;;
  *) skip "this engine's swarm state is '$state' (not inactive or active): cannot use a swarm" ;;
esac

stack="canfleet-swarmtest-$$"
export CANFLEET_STACK="$stack"
export CANFLEET_IMAGE="${CANFLEET_IMAGE:-canfleet:dev}"
swarm() { scripts/docker-swarm.sh "$@"; }
deployed=0
work=$(mktemp -d)

teardown() {
  local rc=$?
  trap - EXIT
  if [ "$keep" = 1 ]; then
    log "--keep: stack left running: CANFLEET_STACK=$stack scripts/docker-swarm.sh status | top | down"
  else
    if [ "$rc" != 0 ] && [ "$deployed" = 1 ]; then
      log "stack tasks:"
      docker stack ps --no-trunc "$stack" 2>&1 | head -40 | sed 's/^/  /' || true
      for s in can0-orchestrator can1-orchestrator; do
        log "$s log (last 25 lines):"
        docker service logs --no-task-ids --tail 25 "${stack}_$s" 2>&1 | sed 's/^/  /' || true
      done
    fi
    if [ "$deployed" = 1 ] || docker network inspect "${stack}_fleet" >/dev/null 2>&1; then
      swarm down >/dev/null 2>&1 || log "WARNING: scripts/docker-swarm.sh down reported something left of $stack"
    fi
    if [ "$made_swarm" = 1 ]; then
      docker swarm leave --force >/dev/null 2>&1 && log "left the swarm this test made" ||
        log "WARNING: docker swarm leave --force failed"
      # The bridge swarm made for its containers' outside traffic outlives the swarm. Best effort:
      # this engine (20.10) keeps an endpoint in it until it restarts ("has active endpoints").
      [ "$had_gwbridge" = 1 ] || docker network rm docker_gwbridge >/dev/null 2>&1 || true
    fi
  fi
  rm -rf "$work"
  if [ "$skipped" = 1 ]; then
    :
  elif [ "$rc" = 0 ]; then
    log "PASSED (${#checks[@]} checks, $(elapsed "$t0"))"
  else
    log "FAILED (exit $rc, $(elapsed "$t0"))"
  fi
  exit "$rc"
}
trap teardown EXIT
trap 'exit 130' INT TERM

# An overlay network is what a stack needs and what some engines cannot make (no VXLAN, ...).
probe="${stack}_probe"
if ! out=$(docker network create --driver overlay --attachable "$probe" 2>&1); then
  skip "this engine cannot create an overlay network: $(echo "$out" | tail -1)"
fi
docker network rm "$probe" >/dev/null

if ! docker image inspect "$CANFLEET_IMAGE" >/dev/null 2>&1; then
  [ "$build" = 1 ] || fail "no image $CANFLEET_IMAGE (tests/docker/run.sh builds it; or run without --no-build)"
  scripts/docker-build.sh --tag "$CANFLEET_IMAGE" 2>&1 | grep -E '^docker-build:|ERROR|error:' || true
  [ "${PIPESTATUS[0]}" = 0 ] || fail "scripts/docker-build.sh failed"
fi

# ---- ports, subnet and shard file of this run ------------------------------------------------------
# Seven free host ports (the last for the browser view) (a running demo stack or compose fleet is not disturbed) and an overlay
# subnet that overlaps no existing network.
read -r p1 p2 p3 p4 p5 p6 p7 < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(7)]
for s in socks: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])')
used_subnets=$(docker network ls -q | xargs -r docker network inspect -f '{{range .IPAM.Config}}{{.Subnet}} {{end}}' 2>/dev/null || true)
subnet=$(python3 -c '
import ipaddress, sys
used = [ipaddress.ip_network(s) for s in sys.argv[1].split() if ":" not in s]
for b in range(150, 250):
    n = ipaddress.ip_network("10.%d.0.0/16" % b)
    if not any(n.overlaps(u) for u in used):
        print(n); break' "$used_subnets")
[ -n "$subnet" ] || fail "no free 10.x.0.0/16 for the overlay network"
export CANFLEET_SWARM_SUBNET="$subnet"
cat >"$work/test.shards" <<EOF
bus can0 bitrate=250000 nodes=10 device=quad-controller broker_port=$p1 control_port=$p2 socketcand_port=$p3
bus can1 bitrate=500000 nodes=10 eds=eds/canfleet-dio16.eds broker_port=$p4 control_port=$p5 socketcand_port=$p6
EOF
log "stack $stack on $subnet; can0 control :$p2 socketcand :$p3, can1 control :$p5 socketcand :$p6; budget $budget s"

# ---- helpers on `canfleet status --json` -------------------------------------------------------------
cli() { swarm cli "$@"; }
# node_get BUS NAME FIELD: one field of one node (last_emcy.code, emcy_count, nmt_state, attached).
node_get() {
  cli "$1" status --json | python3 -c '
import json, sys
name, field = sys.argv[1], sys.argv[2]
for n in json.load(sys.stdin)["nodes"]:
    if n["name"] == name:
        v = n
        for part in field.split("."):
            v = v.get(part, "") if isinstance(v, dict) else ""
        print(str(v).lower() if isinstance(v, bool) else (0 if v == "" else v))
        sys.exit(0)
sys.exit(1)' "$2" "$3"
}
wait_for() { # SECONDS DESCRIPTION COMMAND...
  local limit what=$2 start
  limit=$(bound "$1")
  shift 2
  start=$(date +%s)
  until "$@" >/dev/null 2>&1; do
    [ $(($(date +%s) - start)) -lt "$limit" ] || fail "$what: not seen within $limit s"
    sleep 1
  done
}
expect_eq() { # DESCRIPTION ACTUAL EXPECTED
  python3 -c 'import sys; sys.exit(0 if int(sys.argv[1], 0) == int(sys.argv[2], 0) else 1)' "$2" "$3" ||
    fail "$1: got $2, expected $3"
}
emcy_is() { [ "$(node_get "$1" "$2" emcy_count)" -gt "$3" ] && [ "$(node_get "$1" "$2" last_emcy.code)" = "$4" ]; }
nmt_is() { [ "$(node_get "$1" "$2" nmt_state)" = "$3" ]; }
# top_once: canfleet-top --once at a monitor slot; count_oper BUS counts its operational rows.
top_once() {
  swarm top --once --wait 20 --color never --width 160 --height 200 2>&1
}
count_oper() { # BUS < top output
  grep -cE "^[> ] [^ ]+ +$1 +[0-9]+ +[^ ]+ +operational" || true
}
task_container() { # SERVICE SLOT: the running container of that task (this host)
  docker ps --filter "label=com.docker.swarm.service.name=${stack}_$1" \
    --format '{{.ID}} {{.Label "com.docker.swarm.task.name"}}' | awk -v p="${stack}_$1.$2." 'index($2, p) == 1 {print $1}'
}
sdo() { cli "$1" sdo read "$2" "$3" "$4" "$5"; }
# settle LIMIT WHAT: every node attached and operational. A Quad whose heartbeat consumer timed out
# goes pre-operational (1029h) and stays so until an NMT start; on a starved machine (load average
# far above the core count: processes not scheduled for 1.5 s) that happens without any fault. So
# after a first wait, the buses get an NMT start before each further one, and the note says how
# many were needed. Sets settle_note.
settle() {
  local limit what=$2 start try=0 first
  limit=$(bound "$1")
  start=$(date +%s)
  first=$((limit < 90 ? limit : 90))
  settle_note=""
  until swarm wait --timeout "$([ "$try" = 0 ] && echo "$first" || echo 20)" >"$work/wait.txt" 2>&1; do
    if [ $(($(date +%s) - start)) -ge "$limit" ]; then
      cat "$work/wait.txt" >&2
      fail "$what: not every node operational within $limit s"
    fi
    try=$((try + 1))
    log "$what: $(grep -o 'not every node.*' "$work/wait.txt" | head -1 | cut -c1-300); NMT start again (load average $(cut -d' ' -f1 /proc/loadavg))"
    cli can0 nmt start >/dev/null 2>&1 || true
    cli can1 nmt start >/dev/null 2>&1 || true
  done
  [ "$try" = 0 ] || settle_note="; $try extra NMT start(s): nodes had lost heartbeats on the loaded machine"
}

# ---- 1. deploy two buses of 10 nodes ---------------------------------------------------------------
t=$(date +%s)
deployed=1
swarm up "$work/test.shards" --no-wait || fail "the stack was not deployed"
settle 240 "deploy"
deploy_s=$(($(date +%s) - t))
pass "stack deployed: 2 buses (one orchestrator service each) x 10 nodes, all 20 attached and operational via the control APIs (${deploy_s} s$settle_note)"
figures+=("deploy, 2 orchestrators + 20 nodes, until all operational: ${deploy_s} s")
for bus in can0 can1; do
  [ "$(docker service inspect -f '{{.Spec.Mode.Replicated.Replicas}}' "${stack}_$bus-nodes")" = 10 ] ||
    fail "${stack}_$bus-nodes should have 10 replicas"
done
# Slot 5 is node-ID 5, named can0-node-5; it consumes node 4 (1016h sub 1 = 0004h << 16 | 1500 ms).
expect_eq "can0-node-5 1016h sub 1 (consumer of node 4, 1500 ms, set by the orchestrator)" "$(sdo can0 can0-node-5 0x1016 1 u32)" 0x000405DC
expect_eq "can0-node-5 1017h (producer 500 ms)" "$(sdo can0 can0-node-5 0x1017 0 u16)" 500
expect_eq "can1-node-7 1016h sub 1 (consumer of node 6)" "$(sdo can1 can1-node-7 0x1016 1 u32)" 0x000605DC
pass "node-ID and name from the task slot; the orchestrators configured them (can0-node-5 1016h.1 = 000405DCh, 1017h = 500; can1-node-7 1016h.1 = 000605DCh)"

# ---- 2. published endpoints ----------------------------------------------------------------------
sc_out=$(python3 - "$p3" <<'PY' 2>&1
import socket, sys, time
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=10)
def read():
    try:
        return s.recv(4096).decode(errors="replace")
    except socket.timeout:
        return ""
hi = read()
if "< hi >" not in hi:
    sys.exit("no '< hi >' (got %r)" % hi)
s.sendall(b"< open can0 >"); ok = read()
s.sendall(b"< rawmode >")
data, end = "", time.time() + 10
while "< frame " not in data and time.time() < end:
    data += read()
if "< frame " not in data:
    sys.exit("no frame in raw mode (got %r)" % (ok + data)[:200])
print(data[data.index("< frame "):].split(">")[0] + ">")
PY
) || fail "socketcand of can0 on 127.0.0.1:$p3: $sc_out"
python3 -c 'import socket, sys; socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=5).close()' "$p5" ||
  fail "can1's control API is not published on 127.0.0.1:$p5"
pass "published in host mode: socketcand of can0 on 127.0.0.1:$p3 (hi, open can0, rawmode, $sc_out); can1's control API accepts on 127.0.0.1:$p5"

# ---- 2b. the fleet's token: a Docker secret of the stack ------------------------------------------
docker service inspect -f '{{range .Spec.TaskTemplate.ContainerSpec.Secrets}}{{.File.Name}} {{end}}' "${stack}_can0-orchestrator" |
  grep -q canfleet_token || fail "can0's orchestrator service has no canfleet_token secret"
docker service inspect -f '{{range .Spec.TaskTemplate.ContainerSpec.Secrets}}{{.File.Name}} {{end}}' "${stack}_can0-nodes" |
  grep -q canfleet_token || fail "can0's node service has no canfleet_token secret"
if [ -x build/bin/canfleet ]; then
  out=$(env -u CANFLEET_TOKEN -u CANFLEET_TOKEN_FILE build/bin/canfleet --control "tcp://127.0.0.1:$p2" status 2>&1) &&
    fail "can0's published control API answered a client without the token"
  printf '%s' "$out" | grep -q "refused: no token" || fail "no token: expected a refusal naming it, got: $out"
  pass "the fleet's token is the stack's Docker secret (orchestrator and node services); the nodes joined with it; can0's control API on 127.0.0.1:$p2 refuses a client without it"
else
  pass "the fleet's token is the stack's Docker secret (orchestrator and node services); the nodes joined with it"
fi

# ---- 3. scale can0 to 20 nodes -------------------------------------------------------------------
t=$(date +%s)
swarm scale can0 20 --no-wait || fail "docker service scale of can0 failed"
settle 180 "scale can0 to 20"
scale_s=$(($(date +%s) - t))
expect_eq "can0-node-17 1016h sub 1 (a node added by the scale)" "$(sdo can0 can0-node-17 0x1016 1 u32)" 0x001005DC
pass "docker service scale ${stack}_can0-nodes=20: node-IDs 11..20 attached, configured (can0-node-17 1016h.1 = 001005DCh), 30 nodes operational (${scale_s} s$settle_note)"
figures+=("scale can0 from 10 to 20 nodes, until all operational: ${scale_s} s")

# ---- 4. DDS across the overlay: canfleet-top in a container on it ------------------------------
t=$(date +%s)
for attempt in 1 2 3; do
  top_out=$(top_once) || true
  c0=$(printf '%s\n' "$top_out" | count_oper can0)
  c1=$(printf '%s\n' "$top_out" | count_oper can1)
  [ "$c0" = 20 ] && [ "$c1" = 10 ] && break
  log "canfleet-top attempt $attempt: can0 $c0/20, can1 $c1/10 operational"
  settle 60 "before canfleet-top attempt $((attempt + 1))"
done
if [ "$c0" != 20 ] || [ "$c1" != 10 ]; then
  printf '%s\n' "$top_out" | head -60 >&2
  fail "canfleet-top on the overlay showed can0 $c0/20 and can1 $c1/10 nodes operational"
fi
# The control: the same configuration in a container at an address that is no monitor slot finds no
# writer. What canfleet-top saw came by unicast to its slot (on one host the overlay would carry
# multicast; across hosts it does not, and the stack does not rely on it).
ctl_out=$(docker run --rm --network "${stack}_fleet" -e CANFLEET_DDS_CONFIG= \
  -e "CYCLONEDDS_URI=$(docker network inspect -f '{{index .Labels "canfleet.dds-uri"}}' "${stack}_fleet")" \
  "$CANFLEET_IMAGE" canfleet-top --once --wait 5 --color never --width 160 --height 10 2>&1) || true
printf '%s\n' "$ctl_out" | grep -q ' 0 nodes on 0 buses' ||
  { printf '%s\n' "$ctl_out" | head -5 >&2; fail "a monitor outside the monitor slots saw writers: discovery is not what the stack says"; }
pass "DDS across the overlay, unicast discovery: canfleet-top --once at a monitor slot shows all 30 nodes operational (can0 20, can1 10); the same configuration at an address that is no slot sees 0 nodes ($(elapsed "$t"))"

# ---- 4b. the browser view at a monitor slot ------------------------------------------------------
t=$(date +%s)
swarm web --port "$p7" >"$work/web.log" 2>&1 &
web_pid=$!
web_state() { # prints "can0 N can1 M" operational in /api/state
  python3 - "$p7" <<'PY'
import json, sys, urllib.request
state = json.load(urllib.request.urlopen("http://127.0.0.1:%s/api/state" % sys.argv[1], timeout=5))
count = {"can0": 0, "can1": 0}
for n in state["nodes"]:
    if n.get("nmt") == "operational" and n.get("bus") in count:
        count[n["bus"]] += 1
print("can0", count["can0"], "can1", count["can1"])
PY
}
web_all() { [ "$(web_state 2>/dev/null)" = "can0 20 can1 10" ]; }
wait_for 90 "canfleet web at a monitor slot: /api/state shows can0 20 and can1 10 operational (last: $(web_state 2>&1 | tail -1))" web_all
page=$(python3 -c 'import sys, urllib.request; print(urllib.request.urlopen("http://127.0.0.1:%s/" % sys.argv[1], timeout=5).read().decode())' "$p7")
printf '%s' "$page" | grep -q '<title>canfleet' || fail "canfleet web at a monitor slot did not serve its page"
refused=$(python3 - "$p7" <<'PY'
import sys, urllib.error, urllib.request
req = urllib.request.Request("http://127.0.0.1:%s/api/action" % sys.argv[1], data=b'{"nmt":{"command":"stop"}}',
                             headers={"Content-Type": "application/json"})
try:
    urllib.request.urlopen(req, timeout=5)
    print("accepted")
except urllib.error.HTTPError as e:
    print(e.code)
PY
)
[ "$refused" = 403 ] || fail "canfleet web at a monitor slot (read-only) answered an action with '$refused', not 403"
docker rm -f "$(docker ps -q --filter "label=canfleet.stack=$stack" --filter ancestor="$CANFLEET_IMAGE" | head -1)" >/dev/null 2>&1 || true
kill "$web_pid" 2>/dev/null || true
wait "$web_pid" 2>/dev/null || true
pass "canfleet web at a monitor slot (scripts/docker-swarm.sh web, published on 127.0.0.1:$p7): /api/state shows can0 20 and can1 10 operational from DDS across the overlay, the page is served, an action is refused (403, read-only) ($(elapsed "$t"))"

# ---- 5. kill a node task: its consumer's heartbeat-loss EMCY and its return ------------------------
watch_log="$work/watch.log"
swarm watch --bus can0 --node 4 >"$watch_log" 2>&1 &
watch_pid=$!
# Only events from now on (watch's default): the watcher matches the writers within a second or two.
sleep 3
c4=$(node_get can0 can0-node-4 emcy_count)
victim=$(task_container can0-nodes 3)
[ -n "$victim" ] || fail "no running container for task slot 3 of ${stack}_can0-nodes on this host"
t=$(date +%s)
docker kill "$victim" >/dev/null
# Swarm starts the replacement 2 s after the kill, so node 4's EMCY 8130h may already be followed
# by its 0000h when the control API is first asked: the event stream (canfleet-watch, DDS) and the
# orchestrator's count of EMCYs are the witnesses, and pre-operational lasts until an NMT start.
wait_for 60 "canfleet-watch on the overlay: EMCY 8130h (heartbeat lost) of can0 #4 after docker kill" \
  grep -qE 'can0 #4 (can0-node-4 )?EMCY 8130h' "$watch_log"
emcy_more() { [ "$(node_get can0 can0-node-4 emcy_count)" -gt "$1" ]; }
wait_for 30 "can0-node-4: the orchestrator counts a new EMCY" emcy_more "$c4"
wait_for 30 "can0-node-4 pre-operational after losing node 3's heartbeat (1029h)" nmt_is can0 can0-node-4 pre-operational
loss_s=$(($(date +%s) - t))
pass "docker kill of can0-node-3's task: can0-node-4 EMCY 8130h (canfleet-watch on the overlay; the orchestrator counted it) and pre-operational (control API) (${loss_s} s)"
t=$(date +%s)
new_task() { local c; c=$(task_container can0-nodes 3); [ -n "$c" ] && [ "$c" != "$victim" ]; }
wait_for 60 "swarm replaces the killed task of slot 3" new_task
wait_for 90 "can0-node-3 operational again (configured and started by its orchestrator)" nmt_is can0 can0-node-3 operational
expect_eq "can0-node-3 1016h sub 1 after it came back" "$(sdo can0 can0-node-3 0x1016 1 u32)" 0x000205DC
expect_eq "can0-node-3 1017h after it came back" "$(sdo can0 can0-node-3 0x1017 0 u16)" 500
# The error reset: node 4's EMCY 0000h after its 8130h, in the stream and as the last EMCY the
# orchestrator saw (two EMCYs more than before the kill).
after_reset() { awk '/can0 #4 (can0-node-4 )?EMCY 8130h/ {seen = 1} seen && /can0 #4 (can0-node-4 )?EMCY 0000h/ {ok = 1} END {exit !ok}' "$watch_log"; }
wait_for 60 "canfleet-watch on the overlay: EMCY 0000h (error reset) of can0 #4 after its 8130h" after_reset
wait_for 30 "can0-node-4 EMCY 0000h as the orchestrator's last EMCY of it" emcy_is can0 can0-node-4 "$((c4 + 1))" 0
kill "$watch_pid" 2>/dev/null || true
wait "$watch_pid" 2>/dev/null || true
cli can0 nmt start >/dev/null
settle 90 "NMT start after the kill"
for attempt in 1 2 3; do
  top_out=$(top_once) || true
  c0=$(printf '%s\n' "$top_out" | count_oper can0)
  c1=$(printf '%s\n' "$top_out" | count_oper can1)
  [ "$c0" = 20 ] && [ "$c1" = 10 ] && break
  log "canfleet-top after the kill, attempt $attempt: can0 $c0/20, can1 $c1/10 operational"
  settle 60 "before canfleet-top attempt $((attempt + 1))"
done
[ "$c0" = 20 ] && [ "$c1" = 10 ] || { printf '%s\n' "$top_out" | head -60 >&2; fail "after the kill canfleet-top showed can0 $c0/20, can1 $c1/10 operational"; }
pass "the task came back: same slot, same node-ID and name, reconfigured (1016h.1 = 000205DCh, 1017h = 500), can0-node-4 EMCY 0000h (control API and canfleet-watch); after NMT start 30 operational, and a new canfleet-top sees all 30 operational ($(elapsed "$t"))"
grep -E 'can0 #4 (can0-node-4 )?EMCY (8130|0000)h' "$watch_log" | tail -2 | sed 's/^/swarm-test:   watch: /' || true

# ---- 6. figures ----------------------------------------------------------------------------------
rss_of() { # SERVICE: "n mean min max" of VmRSS (kB) over its containers on this host
  local c pid
  for c in $(docker ps -q --filter "label=com.docker.swarm.service.name=${stack}_$1"); do
    pid=$(docker inspect -f '{{.State.Pid}}' "$c")
    awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true
  done | awk '{n++; s+=$1; if (min == "" || $1 < min) min = $1; if ($1 > max) max = $1}
    END {if (n) printf "%d nodes: mean %.2f MB (%.2f-%.2f)", n, s/n/1024, min/1024, max/1024}'
}
cpu_of() { # SERVICE SECONDS: mean CPU % per container of SERVICE over SECONDS
  local pids c
  pids=$(for c in $(docker ps -q --filter "label=com.docker.swarm.service.name=${stack}_$1"); do docker inspect -f '{{.State.Pid}}' "$c"; done)
  python3 -c '
import os, sys, time
pids, secs = sys.argv[1].split(), float(sys.argv[2])
def ticks():
    t = 0
    for p in pids:
        try:
            f = open("/proc/%s/stat" % p).read().rsplit(")", 1)[1].split()
            t += int(f[11]) + int(f[12])
        except OSError:
            pass
    return t
a = ticks(); time.sleep(secs); b = ticks()
print("%.2f %%" % (100.0 * (b - a) / os.sysconf("SC_CLK_TCK") / secs / max(len(pids), 1)))' "$pids" "$2"
}
figures+=("RSS can0 (quad-controller) $(rss_of can0-nodes); CPU $(cpu_of can0-nodes 5) of a core per node")
figures+=("RSS can1 (generic CiA 401, dio16.eds) $(rss_of can1-nodes); CPU $(cpu_of can1-nodes 5) of a core per node")
one_rss() { rss_of "$1" | sed 's/^1 nodes: mean //; s/ (.*//'; }
figures+=("RSS orchestrator (canfleet up, one bus, 127 node slots): can0 $(one_rss can0-orchestrator), can1 $(one_rss can1-orchestrator); CPU can0 $(cpu_of can0-orchestrator 5) of a core")
figures+=("$(cli can0 status --json | python3 -c '
import json, sys
b = json.load(sys.stdin)["buses"][0]
print("can0 (%d kbit/s, 20 Quads): %.0f frames/s, load %.1f %%" % (b["bitrate"] // 1000, b["frames_per_s"], b["load_percent"]))')")
figures+=("$(cli can1 status --json | python3 -c '
import json, sys
b = json.load(sys.stdin)["buses"][0]
print("can1 (%d kbit/s, 10 generic nodes): %.0f frames/s, load %.1f %%" % (b["bitrate"] // 1000, b["frames_per_s"], b["load_percent"]))')")

# ---- 7. remove the stack: nothing left -------------------------------------------------------------
volumes=$(docker ps -q --filter "label=com.docker.stack.namespace=$stack" | xargs -r docker inspect -f '{{range .Mounts}}{{if eq .Type "volume"}}{{.Name}} {{end}}{{end}}' | xargs)
t=$(date +%s)
deployed=0
out=$(swarm down 2>&1) || { echo "$out" >&2; fail "scripts/docker-swarm.sh down left something behind"; }
for v in $volumes; do
  ! docker volume inspect "$v" >/dev/null 2>&1 || fail "volume $v of the stack is still there"
done
pass "scripts/docker-swarm.sh down: no service, container, network, config, secret or volume of $stack left (volumes used: ${volumes:-none}) ($(elapsed "$t"))"

log "checked:"
for c in "${checks[@]}"; do echo "swarm-test:   - $c"; done
log "figures (this host: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)):"
for f in "${figures[@]}"; do echo "swarm-test:   - $f"; done
