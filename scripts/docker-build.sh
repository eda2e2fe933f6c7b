#!/usr/bin/env bash
# Builds the canfleet image (docker/Dockerfile) from this tree, without any container registry.
#
#   scripts/docker-build.sh [--tag IMAGE] [--base IMAGE] [--builder auto|buildkit|classic]
#                           [--src DIR | --prebuilt BUILD] [--keep-going] [--no-cache]
#                           [-- extra docker build args]
#
#   --tag IMAGE     image to produce (default $CANFLEET_IMAGE or canfleet:dev)
#   --base IMAGE    BASE_IMAGE build argument (default $CANFLEET_BASE_IMAGE or
#                   canfleet/debian:bookworm, made by scripts/docker-base-image.sh when missing;
#                   with a registry, e.g. debian:bookworm-slim)
#   --builder       auto (default): BuildKit (cache mounts for apt and ccache) when some docker
#                   client here can use it, else the classic builder with the mounts stripped
#   --src DIR       build context (default: this repository); e.g. a `git worktree` of HEAD
#   --prebuilt BUILD  ship the executables of BUILD, a CMake build folder of this tree on this host
#                   (built already, or built now), instead of compiling them again in the image:
#                   what scripts/test.sh does, so the image holds the binaries the suite has just
#                   tested. Needs BuildKit and a host of the base image's system (Debian 12), so
#                   the binaries load the same libraries there (docker/stage.sh finds their
#                   packages); otherwise it says so and builds from source.
#   --keep-going    ship the executables that compile, warn about the others (in-progress tree)
#   --no-cache      passed to docker build
# Prints the build time and the image size. Exits non-zero with the reason when docker is missing.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"

tag="${CANFLEET_IMAGE:-canfleet:dev}"
base="${CANFLEET_BASE_IMAGE:-canfleet/debian:bookworm}"
builder=auto
src="$repo"
prebuilt=""
extra=()

say() { echo "docker-build: $*"; }
die() { echo "docker-build: ERROR: $*" >&2; exit "${2:-1}"; }

while [ $# -gt 0 ]; do
  case "$1" in
    --tag) tag="${2:?}"; shift ;;
    --base) base="${2:?}"; shift ;;
    --builder) builder="${2:?}"; shift ;;
    --src) src="$(cd "${2:?}" && pwd)"; shift ;;
    --prebuilt) prebuilt="$(cd "${2:?}" && pwd)" || die "--prebuilt: no folder '$2'"; shift ;;
    --keep-going) extra+=(--build-arg CANFLEET_KEEP_GOING=1) ;;
    --no-cache) extra+=(--no-cache) ;;
    --) shift; extra+=("$@"); break ;;
    -h | --help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
  shift
done

command -v docker >/dev/null || die "docker is not installed" 2
timeout 30 docker info >/dev/null 2>&1 || die "the Docker engine does not answer ('docker info' failed)" 2
[ -f "$src/docker/Dockerfile" ] || die "$src/docker/Dockerfile not found"
[ -f "$src/.dockerignore" ] || say "WARNING: $src/.dockerignore missing: the whole tree (build folders too) is sent"

# The base image: made locally when it is ours; any other (debian:bookworm-slim) is pulled.
if ! docker image inspect "$base" >/dev/null 2>&1; then
  case "$base" in
    canfleet/debian:*) "$repo/scripts/docker-base-image.sh" --tag "$base" ;;
    *) say "base image $base is not here: docker build will pull it (needs a registry)" ;;
  esac
fi

# Which builder. The engine may support BuildKit while the docker CLI in PATH does not without its
# buildx plugin (docker CLI >= 23); an older CLI (Debian's docker.io 20.10, /usr/bin/docker) still
# drives the engine's BuildKit with DOCKER_BUILDKIT=1. Probe each client once with a cache mount.
cli=docker
buildkit_probe() { # $1 = client
  local dir
  dir=$(mktemp -d)
  printf 'FROM %s\nRUN --mount=type=cache,target=/tmp/probe true\n' "$base" >"$dir/Dockerfile"
  DOCKER_BUILDKIT=1 timeout 120 "$1" build -q -t canfleet-buildkit-probe:tmp "$dir" >/dev/null 2>&1
  local rc=$?
  rm -rf "$dir"
  "$1" image rm canfleet-buildkit-probe:tmp >/dev/null 2>&1 || true
  return $rc
}
if [ "$builder" = auto ] || [ "$builder" = buildkit ]; then
  found=""
  for c in docker /usr/bin/docker; do
    command -v "$c" >/dev/null || continue
    if buildkit_probe "$c"; then found="$c"; break; fi
  done
  if [ -n "$found" ]; then
    cli="$found"
    builder=buildkit
  elif [ "$builder" = buildkit ]; then
    die "no docker client here can use BuildKit (no buildx plugin, no pre-23 client)"
  else
    builder=classic
  fi
fi

dockerfile="$src/docker/Dockerfile"
args=(-f "$dockerfile")
if [ "$builder" = classic ]; then
  # Cache mounts are only caches: without BuildKit, drop them.
  mkdir -p "$repo/build-docker"
  dockerfile="$repo/build-docker/Dockerfile.classic"
  # It also builds every stage: drop the prebuilt one, whose prebuilt/ folder is not in this context.
  sed -E -e 's/^RUN( --mount=[^ ]+)+/RUN/' -e '/^# >>> prebuilt/,/^# <<< prebuilt/d' \
    "$src/docker/Dockerfile" >"$dockerfile"
  args=(-f "$dockerfile")
  export DOCKER_BUILDKIT=0
else
  export DOCKER_BUILDKIT=1
  args+=(--progress=plain)
fi

if [ -n "$prebuilt" ]; then
  [ -f "$prebuilt/CMakeCache.txt" ] || die "--prebuilt: $prebuilt is not a CMake build folder"
  # The binaries were linked here: they run in the image only if it is the same system.
  host_os=$(. /etc/os-release && echo "$ID $VERSION_ID")
  image_os=$(docker run --rm "$base" sh -c '. /etc/os-release && echo "$ID $VERSION_ID"') ||
    die "could not read /etc/os-release in $base"
  if [ "$builder" != buildkit ]; then
    say "--prebuilt needs BuildKit (the classic builder compiles the build stage anyway): building from source"
    prebuilt=""
  elif [ "$host_os" != "$image_os" ]; then
    say "--prebuilt: this host is $host_os but $base is $image_os: building from source"
    prebuilt=""
  fi
fi
if [ -n "$prebuilt" ]; then
  context="$repo/build-docker/prebuilt-context"
  rm -rf "$context"
  mkdir -p "$context"
  cp "$src/docker/Dockerfile" "$context/Dockerfile"
  say "staging the executables of $prebuilt (docker/stage.sh)"
  "$src/docker/stage.sh" "$src" "$prebuilt" "$context/prebuilt" 2>&1 | sed 's/^/docker-build: /' ||
    die "docker/stage.sh failed on $prebuilt"
  args=(-f "$context/Dockerfile" --progress=plain --build-arg BINARIES_FROM=prebuilt)
  src="$context"
fi
say "building $tag from $src (base $base, $builder builder via $cli)"
previous=$(docker image inspect -f '{{.Id}}' "$tag" 2>/dev/null || true)
start=$(date +%s)
"$cli" build "${args[@]}" --build-arg "BASE_IMAGE=$base" -t "$tag" "${extra[@]}" "$src"
secs=$(($(date +%s) - start))
# The image the tag pointed to before is now untagged: drop it (kept if a container uses it).
if [ -n "$previous" ] && [ "$previous" != "$(docker image inspect -f '{{.Id}}' "$tag")" ]; then
  docker image rm "$previous" >/dev/null 2>&1 || true
fi
size=$(docker image inspect -f '{{.Size}}' "$tag" | awk '{printf "%.1f MB", $1/1e6}')
say "built $tag in ${secs}s ($builder builder), image size $size"
docker run --rm --entrypoint ls "$tag" /usr/local/bin | sed 's/^/docker-build:   \/usr\/local\/bin\//'
