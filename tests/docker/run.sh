#!/usr/bin/env bash
# System test of the container fleet on the real Docker engine (docker/compose.yaml,
# topologies/docker.textproto): build the image, bring the fleet up under a project of its own
# and on free loopback ports (a running demo is not disturbed), wait until every node is
# operational, silence quad-5 three ways and check what its heartbeat consumers report, bring it
# back each time, tear everything down (always, also on failure or Ctrl-C).
#
#   tests/docker/run.sh [--no-build | --prebuilt BUILD] [--keep]
#     --no-build   use the existing image (default: scripts/docker-build.sh, fast when cached)
#     --prebuilt BUILD  make the image of the executables in the build folder BUILD
#                  (scripts/docker-build.sh --prebuilt): scripts/test.sh's way, no second compile
#     --keep       leave the fleet running at the end (for a look; `scripts/docker-fleet.sh down`
#                  with the printed CANFLEET_PROJECT removes it)
# Environment: CANFLEET_DOCKER_SRC=DIR builds the image from DIR (scripts/docker-build.sh --src),
#   e.g. `git archive HEAD | tar -x -C DIR` of the committed tree while the working tree has someone's
#   half-written change; CANFLEET_IMAGE (default canfleet:dev).
#
# Prints "SKIPPED: <reason>" and exits 0 when no Docker engine answers; it never reports a pass
# without having run. Exit 1 on any failed check ("FAIL: ..."), 2 on bad arguments.
#
# What it checks (quad-6 and dio-20 consume quad-5's heartbeat, 1500 ms; topologies/docker.textproto):
#  0. a clean machine: scripts/install-deps.sh in a fresh container of the project's base image
#     (scripts/docker-base-image.sh), then `install-deps.sh --check`: every program a script or test
#     calls is there (CANFLEET_DEPS_FRESH=1 repeats the install even when its result is cached)
#  1. every node attached to the broker and operational, read through the control API published on
#     127.0.0.1 (host CLI, build/bin/canfleet, when built); the orchestrator configured the external
#     nodes: quad-6's RPDO1 COB-ID 1400h sub 1 = 185h, quad-5's 1016h sub 1 = 000705DCh
#  2. socketcand of can0 on its published loopback port: handshake and a frame in raw mode (compose.yaml
#     runs canfleet up --socketcand-bind 0.0.0.0)
#  3. telemetry over DDS across containers: canfleet-top --once in a container on the fleet's
#     network shows all 5 nodes operational
#  4. for each of `docker stop`, `docker kill` and `docker network disconnect` of quad-5:
#     - quad-6 sends EMCY 8130h and holds 1003h sub 1 = 08058130h (Quad manual §4.1: description 08h
#       "lost heartbeat", channel 05h = the producer's node-ID; EMCY code 8130h CiA 301 §7.2.7.1),
#       error register 1001h bit 0 set (manual §4.2) and goes pre-operational (1029h sub 1 = 0,
#       manual §3.1.9, CiA 301 §7.2.8.3.2.2 heartbeat consumer)
#     - dio-20 (generic CiA 301 node) sends EMCY 8130h too
#     - quad-5 back (docker start / network connect): quad-6 sends EMCY 0000h (error reset); after
#       stop/kill quad-5 boots again and the orchestrator configures and starts it again (operational,
#       1016h sub 1 = 000705DCh, 1017h = 500 read back); after a disconnect the same process is back,
#       having itself lost quad-7's heartbeat (its own EMCY, pre-operational); after
#       `canfleet nmt start` every node is operational again
#  5. virtual time: quad-5 in a container of its own joins a `canfleet up --time virtual` fleet (in a
#     container) as an external node started with `canfleet-node --time virtual`; configured over the
#     bus, its heartbeat loss gives quad-6 EMCY 8130h and 1003h = 08058130h as in real time
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$repo"

build=1
keep=0
prebuilt=""
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0 ;;
    --keep) keep=1 ;;
    --prebuilt)
      [ $# -ge 2 ] || { echo "tests/docker/run.sh: --prebuilt needs a build folder" >&2; exit 2; }
      prebuilt=$2
      shift
      ;;
    -h | --help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; exit 0 ;;
    *) echo "tests/docker/run.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done

log() { echo "docker-test: $*"; }
checks=()
unchecked=()
pass() { checks+=("$*"); log "ok: $*"; }
fail() {
  echo "docker-test: FAIL: $*" >&2
  exit 1
}

# ---- skip only when there is no engine -----------------------------------------------------------
if ! command -v docker >/dev/null; then
  echo "docker-test: SKIPPED: no 'docker' command on this machine (the container fleet test needs a Docker engine)"
  exit 0
fi
if ! timeout 30 docker info >/dev/null 2>&1; then
  echo "docker-test: SKIPPED: the Docker engine does not answer ('docker info' failed or timed out)"
  exit 0
fi
# ---- 0. a clean machine: the install step in a fresh container of the base image -----------------
# scripts/install-deps.sh runs in a new container of the project's minimal Debian 12 base image (as a
# new user's machine), then its --check looks for every program a script or test calls: one that
# only the developers' machines happen to have fails here. The installed container is kept as an
# image named after the base image and the script's content, so later runs repeat only the check
# until either changes (CANFLEET_DEPS_FRESH=1 installs afresh anyway).
clean_machine() {
  local base="${CANFLEET_BASE_IMAGE:-canfleet/debian:bookworm}" key image name t out
  t=$(date +%s)
  if ! docker image inspect "$base" >/dev/null 2>&1; then
    case "$base" in
      canfleet/debian:*) scripts/docker-base-image.sh --tag "$base" || fail "scripts/docker-base-image.sh could not make $base" ;;
      *) fail "base image $base is not here (and is not ours to make)" ;;
    esac
  fi
  key=$({ docker image inspect -f '{{.Id}}' "$base"; cat scripts/install-deps.sh; } | sha256sum | cut -c1-16)
  image="canfleet/install-deps-check:$key"
  if [ "${CANFLEET_DEPS_FRESH:-0}" = 1 ] || ! docker image inspect "$image" >/dev/null 2>&1; then
    name="canfleet-install-deps-$$"
    mkdir -p build-docker
    # docker cp rather than a bind mount: works with an engine that does not see this file system.
    docker create --name "$name" "$base" bash /opt/install-deps.sh >/dev/null || fail "docker create from $base failed"
    docker cp scripts/install-deps.sh "$name:/opt/install-deps.sh" >/dev/null
    if ! timeout 1800 docker start -a "$name" >build-docker/install-deps.log 2>&1; then
      tail -n 20 build-docker/install-deps.log >&2
      docker rm -f "$name" >/dev/null 2>&1 || true
      fail "scripts/install-deps.sh failed in a fresh container of $base (log: build-docker/install-deps.log)"
    fi
    docker commit "$name" "$image" >/dev/null || fail "docker commit of the installed container failed"
    docker rm "$name" >/dev/null
    # Older results (another script or base image) are of no further use.
    docker image ls --format '{{.Repository}}:{{.Tag}}' canfleet/install-deps-check | grep -vx "$image" |
      xargs -r docker rmi >/dev/null 2>&1 || true
  fi
  out=$(docker run --rm "$image" bash /opt/install-deps.sh --check 2>&1) ||
    fail "after scripts/install-deps.sh in a fresh container of $base: $out"
  pass "clean machine: scripts/install-deps.sh in a fresh $base container, then every program found (${out#install-deps: }, $(elapsed "$t"))"
}
t0=$(date +%s)
elapsed() { echo "$(($(date +%s) - $1)) s"; }
clean_machine

if ! docker compose version >/dev/null 2>&1 && ! command -v docker-compose >/dev/null; then
  fail "a Docker engine answers but no compose tool is installed ('docker compose' v2 or 'docker-compose')"
fi
command -v python3 >/dev/null || fail "python3 is needed to read canfleet status --json"

# ---- a project and host ports of its own ---------------------------------------------------------
export CANFLEET_PROJECT="canfleet-test-$$"
export CANFLEET_IMAGE="${CANFLEET_IMAGE:-canfleet:dev}"
read -r CANFLEET_CONTROL_PORT CANFLEET_BROKER_PORT CANFLEET_CAN0_PORT CANFLEET_CAN1_PORT < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(4)]
for s in socks: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])')
export CANFLEET_CONTROL_PORT CANFLEET_BROKER_PORT CANFLEET_CAN0_PORT CANFLEET_CAN1_PORT
# The fleet's network is a bridge of its own: DDS traffic stays on it whatever the domain.
fleet() { scripts/docker-fleet.sh "$@"; }

teardown() {
  local rc=$?
  if [ "$keep" = 1 ]; then
    log "--keep: fleet left running: CANFLEET_PROJECT=$CANFLEET_PROJECT CANFLEET_CONTROL_PORT=$CANFLEET_CONTROL_PORT"
  else
    if [ "$rc" != 0 ]; then
      log "orchestrator log (last 60 lines):"
      fleet compose logs --no-color --tail 60 orchestrator 2>&1 | sed 's/^/  /' || true
    fi
    fleet down >/dev/null 2>&1 || log "WARNING: 'compose down' of $CANFLEET_PROJECT failed"
    docker rm -f "$CANFLEET_PROJECT-vt-orchestrator" "$CANFLEET_PROJECT-vt-quad-5" >/dev/null 2>&1 || true
    if [ -n "${vt_dir:-}" ]; then rm -rf "$vt_dir"; fi
    log "fleet $CANFLEET_PROJECT removed"
  fi
  if [ "$rc" = 0 ]; then
    log "PASSED (${#checks[@]} checks passed, ${#unchecked[@]} not checked, $(elapsed "$t0"))"
  else
    log "FAILED (exit $rc)"
  fi
}
trap teardown EXIT
trap 'exit 130' INT TERM

# ---- static: the compose file parses in every tool that is here ---------------------------------
# The fleet's token file the compose file's secret names (scripts/docker-fleet.sh makes it).
fleet network >/dev/null 2>&1 || true
[ -s "${CANFLEET_TOKEN_HOST_FILE:-$repo/build-docker/secrets/canfleet-token}" ] ||
  fail "scripts/docker-fleet.sh did not make the fleet's token file"
if command -v docker-compose >/dev/null; then
  docker-compose -f docker/compose.yaml config -q || fail "docker-compose 1.x refuses docker/compose.yaml"
  pass "docker-compose $(docker-compose version --short) accepts docker/compose.yaml"
fi
if docker compose version >/dev/null 2>&1; then
  docker compose -f docker/compose.yaml config -q || fail "docker compose v2 refuses docker/compose.yaml"
  pass "docker compose v2 accepts docker/compose.yaml"
fi
if docker stack config --help >/dev/null 2>&1; then
  docker stack config -c docker/compose.yaml -c docker/stack.yaml >/dev/null 2>"$repo/build-docker-stack-config.err" ||
    { cat "$repo/build-docker-stack-config.err" >&2; rm -f "$repo/build-docker-stack-config.err"; fail "docker stack config refuses docker/compose.yaml + docker/stack.yaml"; }
  rm -f "$repo/build-docker-stack-config.err"
  pass "docker stack config accepts docker/compose.yaml + docker/stack.yaml"
fi

# ---- image ---------------------------------------------------------------------------------------
if [ "$build" = 1 ]; then
  t=$(date +%s)
  scripts/docker-build.sh --tag "$CANFLEET_IMAGE" ${CANFLEET_DOCKER_SRC:+--src "$CANFLEET_DOCKER_SRC"} \
    ${prebuilt:+--prebuilt "$prebuilt"} 2>&1 | grep -E '^docker-build:|ERROR|error:' || true
  [ "${PIPESTATUS[0]}" = 0 ] || fail "scripts/docker-build.sh failed"
  log "image $CANFLEET_IMAGE built in $(elapsed "$t")"
fi
docker image inspect "$CANFLEET_IMAGE" >/dev/null 2>&1 || fail "no image $CANFLEET_IMAGE (run without --no-build)"

# ---- helpers on `canfleet status --json` ---------------------------------------------------------
cli() { fleet cli "$@"; }
status_json() { cli status --json; }
# node_get NAME FIELD: one field of one node from status (last_emcy.code, emcy_count, nmt_state, attached).
node_get() {
  status_json | python3 -c '
import json, sys
name, field = sys.argv[1], sys.argv[2]
for n in json.load(sys.stdin)["nodes"]:
    if n["name"] == name:
        v = n
        for part in field.split("."):
            v = v.get(part, "") if isinstance(v, dict) else ""
        print(str(v).lower() if isinstance(v, bool) else v)
        sys.exit(0)
sys.exit(1)' "$1" "$2"
}
# wait_for SECONDS DESCRIPTION COMMAND...: polls COMMAND every second until it succeeds.
wait_for() {
  local limit=$1 what=$2 start
  shift 2
  start=$(date +%s)
  until "$@" >/dev/null 2>&1; do
    [ $(($(date +%s) - start)) -lt "$limit" ] || fail "$what: not seen within $limit s"
    sleep 1
  done
}
sdo_u32() { cli sdo read "$1" "$2" "$3" u32; }
sdo_u8() { cli sdo read "$1" "$2" "$3" u8; }
sdo_u16() { cli sdo read "$1" "$2" "$3" u16; }
expect_eq() { # DESCRIPTION ACTUAL EXPECTED (numbers, any base python reads)
  python3 -c 'import sys; sys.exit(0 if int(sys.argv[1], 0) == int(sys.argv[2], 0) else 1)' "$2" "$3" ||
    fail "$1: got $2, expected $3"
}
hex() { python3 -c 'import sys; print("%08Xh" % int(sys.argv[1], 0))' "$1"; }
emcy_is() { [ "$(node_get "$1" emcy_count)" -gt "$2" ] && [ "$(node_get "$1" last_emcy.code)" = "$3" ]; }
emcy_is_any() { [ "$(node_get "$1" emcy_count)" -gt "$2" ]; }
nmt_is() { [ "$(node_get "$1" nmt_state)" = "$2" ]; }
attached_is() { [ "$(node_get "$1" attached)" = "$2" ]; }

# ---- 1. up --------------------------------------------------------------------------------------
t=$(date +%s)
log "project $CANFLEET_PROJECT, control API 127.0.0.1:$CANFLEET_CONTROL_PORT, socketcand 127.0.0.1:$CANFLEET_CAN0_PORT/$CANFLEET_CAN1_PORT"
fleet compose up -d || fail "compose up failed"
fleet wait --timeout 240 || fail "the fleet did not become operational"
pass "fleet up, 5 nodes attached and operational via the control API on 127.0.0.1:$CANFLEET_CONTROL_PORT ($(elapsed "$t"))"
for n in quad-5 quad-6 quad-7 dio-20 quad-9; do
  [ "$(node_get $n process)" = external ] || fail "$n: process should be 'external' (its own container)"
done
expect_eq "quad-6 1400h sub 1 (RPDO1 COB-ID, set by the orchestrator)" "$(sdo_u32 quad-6 0x1400 1)" 0x185
expect_eq "quad-5 1016h sub 1 (consumer of quad-7, 1500 ms)" "$(sdo_u32 quad-5 0x1016 1)" 0x000705DC
pass "the orchestrator configured the external nodes (quad-6 1400h.1 = 185h, quad-5 1016h.1 = 000705DCh)"

# The fleet's token (docs/security.md): the control API listens on every address of its container,
# so it lets in only clients with the Docker secret's token. The nodes joined with it (above).
if [ -x build/bin/canfleet ]; then
  out=$(env -u CANFLEET_TOKEN -u CANFLEET_TOKEN_FILE build/bin/canfleet --control "tcp://127.0.0.1:$CANFLEET_CONTROL_PORT" status 2>&1) &&
    fail "the compose fleet's control API answered a client without the token"
  printf '%s' "$out" | grep -q "refused: no token" || fail "no token: expected a refusal naming it, got: $out"
  wrong=$(mktemp)
  echo "not-the-fleet-token-0123456789" >"$wrong"
  out=$(CANFLEET_TOKEN_FILE="$wrong" build/bin/canfleet --control "tcp://127.0.0.1:$CANFLEET_CONTROL_PORT" nmt stop 2>&1) &&
    fail "the compose fleet's control API took a wrong token"
  rm -f "$wrong"
  printf '%s' "$out" | grep -q "refused: wrong token" || fail "wrong token: expected a refusal naming it, got: $out"
  [ "$(node_get quad-5 nmt_state)" = operational ] || fail "the refused nmt stop reached the nodes"
  pass "the fleet's token from a Docker secret: the nodes joined with it; the control API refuses a client without it ('refused: no token') and with a wrong one ('refused: wrong token'; the nmt stop did nothing)"
else
  unchecked+=("the control API's refusals of clients without the token (needs build/bin/canfleet on the host)")
fi
grep -q "canfleet_token" <(docker inspect -f '{{range .Mounts}}{{.Destination}} {{end}}' "$(fleet compose ps -q orchestrator)") ||
  fail "the orchestrator's container has no /run/secrets/canfleet_token"
net=$(fleet network)

# ---- 2. DDS telemetry across containers -----------------------------------------------------------
top_out=$(timeout 90 docker run --rm --network "$net" "$CANFLEET_IMAGE" \
  canfleet-top --once --color never --width 200 --height 40 2>&1) || true
# A node row: the selection marker column, the node's name, bus, node-ID, device, NMT state.
rows=$(printf '%s\n' "$top_out" | grep -cE '^[> ] [^ ]+ +can[01] +[0-9]+ +(quad-controller|generic) +operational' || true)
if [ "$rows" -ne 5 ]; then
  printf '%s\n' "$top_out" >&2
  fail "canfleet-top in a container on $net showed $rows of 5 nodes operational"
fi
pass "DDS telemetry across containers: canfleet-top --once on network $net shows 5 nodes operational"

# canfleet web in a container on the same network: the page's state from the fleet's DDS telemetry
# (its files from the image, /usr/local/share/canfleet/web); asked with bash's /dev/tcp.
web_out=$(timeout 120 docker run --rm --network "$net" "$CANFLEET_IMAGE" bash -c '
  canfleet web --listen 127.0.0.1:8080 --read-only --ready-file /tmp/web.ready >/tmp/web.log 2>&1 &
  for _ in $(seq 100); do [ -f /tmp/web.ready ] && break; sleep 0.1; done
  [ -f /tmp/web.ready ] || { cat /tmp/web.log; exit 1; }
  for _ in $(seq 60); do
    out=""
    if exec 3<>/dev/tcp/127.0.0.1/8080; then
      printf "GET /api/state HTTP/1.0\r\nHost: x\r\n\r\n" >&3
      out=$(cat <&3)
      exec 3<&-
    fi
    n=$(printf "%s" "$out" | grep -o "\"nmt\":\"operational\"" | wc -l)
    [ "$n" -ge 5 ] && { echo "operational: $n"; exit 0; }
    sleep 1
  done
  printf "%s\n" "$out" | head -c 2000; cat /tmp/web.log; exit 1' 2>&1) ||
  { printf '%s\n' "$web_out" >&2; fail "canfleet web in a container on $net did not show the 5 nodes operational"; }
pass "canfleet web in a container on network $net: /api/state shows the 5 nodes operational (DDS telemetry, the image's page files)"

# ---- socketcand on the host's loopback -----------------------------------------------------------
# `< hi >` from can0's published port, then a frame in raw mode (socketcand protocol). compose.yaml
# runs `canfleet up --socketcand-bind 0.0.0.0`: the container's loopback is not where published ports arrive.
sc_out=$(python3 - "$CANFLEET_CAN0_PORT" <<'PY' 2>&1
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
) && sc_rc=0 || sc_rc=$?
if [ "$sc_rc" = 0 ]; then
  pass "socketcand of can0 on 127.0.0.1:$CANFLEET_CAN0_PORT: hi, open can0, rawmode, $sc_out"
else
  fail "socketcand of can0 on 127.0.0.1:$CANFLEET_CAN0_PORT: $sc_out"
fi

container_of() { fleet compose ps -q "$1"; }
q5=$(container_of quad-5)
[ -n "$q5" ] || fail "no container for quad-5"

# ---- 3. heartbeat loss, three ways ---------------------------------------------------------------
loss_and_back() { # METHOD: stop | kill | disconnect
  local how=$1 c6 c20 t
  c6=$(node_get quad-6 emcy_count)
  c20=$(node_get dio-20 emcy_count)
  t=$(date +%s)
  case "$how" in
    stop) docker stop "$q5" >/dev/null ;;
    kill) docker kill "$q5" >/dev/null ;;
    disconnect) docker network disconnect "$net" "$q5" ;;
  esac
  # 1500 ms consumer time; generous bound for a loaded machine.
  wait_for 60 "quad-6 EMCY 8130h after docker $how of quad-5" emcy_is quad-6 "$c6" 33072
  wait_for 60 "dio-20 EMCY 8130h after docker $how of quad-5" emcy_is dio-20 "$c20" 33072
  local e1003 e1001
  e1003=$(sdo_u32 quad-6 0x1003 1)
  expect_eq "quad-6 1003h sub 1 after docker $how of quad-5" "$e1003" 0x08058130
  e1001=$(sdo_u8 quad-6 0x1001 0)
  python3 -c 'import sys; sys.exit(0 if int(sys.argv[1]) & 1 else 1)' "$e1001" ||
    fail "quad-6 error register 1001h = $e1001 after docker $how of quad-5: bit 0 (generic error) not set"
  wait_for 30 "quad-6 pre-operational after docker $how of quad-5 (1029h sub 1 = 0)" nmt_is quad-6 pre-operational
  if [ "$how" != disconnect ]; then
    wait_for 30 "quad-5 detached after docker $how" attached_is quad-5 false
  fi
  pass "docker $how quad-5: quad-6 EMCY 8130h, 1003h.1 = $(hex "$e1003"), 1001h = $e1001, pre-operational; dio-20 EMCY 8130h ($(elapsed "$t"))"

  # Back: a fresh boot of quad-5 (configured again by the orchestrator), or the same process
  # reachable again after a network disconnect.
  t=$(date +%s)
  local c6b c5b restarted=0
  c6b=$(node_get quad-6 emcy_count)
  c5b=$(node_get quad-5 emcy_count)
  case "$how" in
    stop | kill) docker start "$q5" >/dev/null ;;
    disconnect) docker network connect "$net" "$q5" ;;
  esac
  if [ "$how" = disconnect ]; then
    # The node's TCP connection survives when the container gets its address back; if it does not
    # (another address, or the broker gave up on it), restart the container.
    if ! (wait_for 30 "x" emcy_is quad-6 "$c6b" 0) 2>/dev/null; then
      log "quad-5 did not come back on its own after network connect within 30 s; docker restart"
      docker restart "$q5" >/dev/null
      restarted=1
    fi
  fi
  wait_for 90 "quad-6 EMCY 0000h (error reset) after quad-5 is back" emcy_is quad-6 "$c6b" 0
  local note=""
  if [ "$how" = disconnect ] && [ "$restarted" = 0 ]; then
    # Cut off, quad-5 lost quad-7's heartbeat too: its own EMCY 8130h (channel 07h) arrives once it
    # is reconnected, and 1029h took it to pre-operational; nothing rebooted it.
    wait_for 30 "quad-5's own EMCY after it was cut off (it consumes quad-7's heartbeat)" \
      emcy_is_any quad-5 "$c5b"
    wait_for 30 "quad-5 pre-operational after it was cut off (lost quad-7's heartbeat, 1029h)" \
      nmt_is quad-5 pre-operational
    # The two directions of its TCP session recover separately: the broker's segments to quad-5
    # may wait out a retransmission back-off of seconds. quad-5's error reset (0000h: quad-7's
    # heartbeat reached it again) shows that frames reach it again, so an SDO request will too.
    wait_for 90 "quad-5 receives the bus again after it was cut off (its EMCY 0000h)" \
      emcy_is quad-5 "$c5b" 0
    note="same process, TCP session survived; quad-5 itself reported losing quad-7 (EMCY) and went pre-operational"
  else
    # A new process: boot-up, configuration by the orchestrator, NMT start by the orchestrator.
    wait_for 90 "quad-5 operational again after docker $how (configured and started by the orchestrator)" \
      nmt_is quad-5 operational
    note="rebooted, configured and started again by the orchestrator"
  fi
  expect_eq "quad-5 1016h sub 1 after it came back" "$(sdo_u32 quad-5 0x1016 1)" 0x000705DC
  expect_eq "quad-5 1017h after it came back" "$(sdo_u16 quad-5 0x1017 0)" 500
  cli nmt start >/dev/null
  fleet wait --timeout 90 >/dev/null || fail "not every node operational after NMT start (after docker $how)"
  pass "quad-5 back after docker $how ($note): 1016h.1 = 000705DCh, 1017h = 500, quad-6 EMCY 0000h; all operational after NMT start ($(elapsed "$t"))"
}

loss_and_back stop
loss_and_back kill
loss_and_back disconnect

# ---- 5. virtual time: a node in a container joins a fleet in lock-step virtual time ---------------
# `canfleet up --time virtual` in a container (the orchestrator starts quad-6 itself) and quad-5 as an
# external node in a container of its own, `canfleet-node --time virtual`: the same protocol as a
# local node (orchestrator/broker/README.md "Virtual time"). Both share the host's network stack
# (--network host), so the broker stays on loopback. The fleet's time starts once both joined; the
# orchestrator configures quad-5 over the bus; a heartbeat loss of quad-5 is served at the current
# simulated time and quad-6 reports it as in real time (Quad manual §4.1: EMCY 8130h, 1003h sub 1 =
# 08058130h).
virtual_time_in_containers() {
  local t control broker
  t=$(date +%s)
  vt_dir=$(mktemp -d /tmp/canfleet-docker-vt-XXXXXX)
  chmod 0755 "$vt_dir" # the image's user reads the topology from it (mktemp makes it 0700)
  read -r control broker < <(python3 -c '
import socket
socks = [socket.socket() for _ in range(2)]
for s in socks: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in socks])')
  cat >"$vt_dir/vt.textproto" <<TOPOLOGY
name: "docker-virtual-time"
orchestrator { state_root: "/tmp/docker-virtual-time" }
time { mode: VIRTUAL speed: 20 }
bus { name: "can0" bitrate: 250000 }
node { name: "quad-5" device: "quad-controller" node_id: 5 bus: "can0" external: true
       heartbeat { producer_ms: 200 } }
node { name: "quad-6" device: "quad-controller" node_id: 6 bus: "can0"
       heartbeat { producer_ms: 200 consumer { node: "quad-5" timeout_ms: 1000 } } }
TOPOLOGY
  docker run -d --name "$CANFLEET_PROJECT-vt-orchestrator" --network host -v "$vt_dir:/vt" "$CANFLEET_IMAGE" \
    canfleet up /vt/vt.textproto --control "tcp://127.0.0.1:$control" --listen "tcp://127.0.0.1:$broker" \
    --no-telemetry >/dev/null || fail "virtual time: the orchestrator container did not start"
  docker run -d --name "$CANFLEET_PROJECT-vt-quad-5" --network host "$CANFLEET_IMAGE" \
    canfleet-node --time virtual --device quad-controller --node-id 5 --name quad-5 \
    --bus "can0@tcp://127.0.0.1:$broker" --no-telemetry >/dev/null ||
    fail "virtual time: the quad-5 container did not start"
  vt_cli() { docker run --rm --network host "$CANFLEET_IMAGE" canfleet --control "tcp://127.0.0.1:$control" "$@"; }
  vt_get() { # NODE FIELD (NODE "-" and FIELD virtual_time: the fleet's)
    vt_cli status --json | python3 -c '
import json, sys
s = json.load(sys.stdin)
if sys.argv[2] == "virtual_time":
    print(str(s.get("virtual_time", False)).lower()); sys.exit(0)
for n in s["nodes"]:
    if n["name"] == sys.argv[1]:
        v = n
        for part in sys.argv[2].split("."):
            v = v.get(part, "") if isinstance(v, dict) else ""
        print(v); sys.exit(0)
sys.exit(1)' "$1" "$2"
  }
  vt_is() { [ "$(vt_get "$1" "$2")" = "$3" ]; }
  wait_for 120 "virtual time: quad-5 (its own container) operational" vt_is quad-5 nmt_state operational
  wait_for 60 "virtual time: quad-6 operational" vt_is quad-6 nmt_state operational
  vt_is - virtual_time true || fail "virtual time: canfleet status does not say the fleet runs in virtual time"
  docker logs "$CANFLEET_PROJECT-vt-quad-5" 2>&1 | grep -q "virtual time" ||
    fail "virtual time: quad-5's log does not show a connection in virtual time"
  expect_eq "virtual time: quad-5 1017h (set by the orchestrator over the bus)" \
    "$(vt_cli sdo read quad-5 0x1017 0 u16)" 200
  vt_cli fault inject heartbeat-loss --node quad-5 >/dev/null || fail "virtual time: fault inject refused"
  wait_for 60 "virtual time: quad-6 EMCY 8130h after quad-5's heartbeat loss" \
    vt_is quad-6 last_emcy.code 33072
  expect_eq "virtual time: quad-6 1003h sub 1" "$(vt_cli sdo read quad-6 0x1003 1 u32)" 0x08058130
  pass "virtual time: quad-5 in a container joined a fleet in lock-step virtual time, configured over the bus (1017h = 200); its heartbeat loss gave quad-6 EMCY 8130h and 1003h = 08058130h ($(elapsed "$t"))"
  docker rm -f "$CANFLEET_PROJECT-vt-orchestrator" "$CANFLEET_PROJECT-vt-quad-5" >/dev/null 2>&1 || true
}
virtual_time_in_containers

log "checked:"
for c in "${checks[@]}"; do echo "docker-test:   - $c"; done
for c in "${unchecked[@]}"; do echo "docker-test:   - NOT CHECKED: $c"; done
tests/docker/swarm.sh --no-build # the same image as a swarm stack, sharded by bus (SKIPPED where the engine cannot run a swarm)
