# The fleet's token for the container fleets (docs/security.md), sourced by scripts/docker-fleet.sh
# and scripts/docker-swarm.sh: CANFLEET_TOKEN_HOST_FILE (default build-docker/secrets/canfleet-token)
# and ensure_fleet_token, which makes it once: random (128 bits, hex), readable only through a
# folder its owner alone may enter (the file itself must be readable by the containers' user, which
# is not the host's). Needs $repo set and a `say` function.
export CANFLEET_TOKEN_HOST_FILE="${CANFLEET_TOKEN_HOST_FILE:-$repo/build-docker/secrets/canfleet-token}"
ensure_fleet_token() {
  [ -s "$CANFLEET_TOKEN_HOST_FILE" ] && return 0
  local dir tmp
  dir=$(dirname "$CANFLEET_TOKEN_HOST_FILE")
  mkdir -p "$dir"
  chmod 700 "$dir"
  tmp=$(mktemp "$dir/.token.XXXXXX")
  od -An -N16 -tx1 /dev/urandom | tr -d ' \n' >"$tmp"
  echo >>"$tmp"
  chmod 644 "$tmp"
  mv "$tmp" "$CANFLEET_TOKEN_HOST_FILE"
  say "made the fleet's token: $CANFLEET_TOKEN_HOST_FILE"
}
