#!/usr/bin/env bash
# Produces the local Debian 12 (bookworm) base image without any container registry:
# debootstrap a minimal bookworm (variant=minbase) from the Debian mirror this machine's apt
# already uses, clean it, and `docker import` it.
#
#   scripts/docker-base-image.sh [--force] [--tag IMAGE] [--cache-dir DIR] [--max-age-days N]
#
#   --force          rebuild the rootfs and re-import even if the image / a recent rootfs exist
#   --tag IMAGE      image name (default $CANFLEET_BASE_IMAGE or canfleet/debian:bookworm)
#   --cache-dir DIR  where the rootfs is kept between runs (default build-docker/)
#   --max-age-days N reuse a cached rootfs younger than N days (default 7)
#
# Environment: DEBIAN_MIRROR overrides the mirror found in apt's sources;
# CANFLEET_DEBOOTSTRAP_TIMEOUT bounds debootstrap (seconds, default 900).
# Idempotent: exits 0 at once when the image exists (unless --force).
# Exit codes: 0 done/already there, 1 usage, 2 docker unavailable, 3 debootstrap unavailable,
# 4 no Debian mirror found, 5 debootstrap failed or timed out, 6 import failed.
set -euo pipefail
cd "$(dirname "$0")/.."

tag="${CANFLEET_BASE_IMAGE:-canfleet/debian:bookworm}"
cache_dir="build-docker"
max_age_days=7
force=0
suite=bookworm
timeout_s="${CANFLEET_DEBOOTSTRAP_TIMEOUT:-900}"

say() { echo "docker-base-image: $*"; }
die() {
  local code=$1
  shift
  echo "docker-base-image: ERROR: $*" >&2
  exit "$code"
}

while [ $# -gt 0 ]; do
  case "$1" in
    --force) force=1 ;;
    --tag) tag="${2:?--tag needs a value}"; shift ;;
    --cache-dir) cache_dir="${2:?--cache-dir needs a value}"; shift ;;
    --max-age-days) max_age_days="${2:?--max-age-days needs a value}"; shift ;;
    -h | --help) awk 'NR > 1 && /^#/ {sub(/^# ?/, ""); print; next} NR > 1 {exit}' "$0"; exit 0 ;;
    *) die 1 "unknown argument '$1' (see --help)" ;;
  esac
  shift
done

# --- docker -------------------------------------------------------------------------------
command -v docker >/dev/null || die 2 "docker is not installed (no 'docker' command in PATH)"
timeout 30 docker info >/dev/null 2>&1 ||
  die 2 "the Docker engine does not answer ('docker info' failed): is dockerd running and may $(id -un) use it?"

if [ "$force" -eq 0 ] && docker image inspect "$tag" >/dev/null 2>&1; then
  say "image $tag already exists ($(docker image inspect -f '{{.Created}}' "$tag")); --force rebuilds it"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || die 3 "debootstrap must run as root and sudo is not available"
  sudo="sudo"
fi

# --- the Debian mirror apt already uses -----------------------------------------------------
# Prints "URI SUITE" for every enabled Debian 'deb' entry of apt's sources (one-line and deb822).
apt_entries() {
  local f
  if [ -f /etc/apt/sources.list ]; then
    # deb [options] URI SUITE COMPONENTS...
    sed -E 's/#.*//; s/\[[^]]*\]//' /etc/apt/sources.list | awk '$1 == "deb" && NF >= 3 {print $2, $3}'
  fi
  for f in /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    sed -E 's/#.*//; s/\[[^]]*\]//' "$f" | awk '$1 == "deb" && NF >= 3 {print $2, $3}'
  done
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    # deb822 stanzas separated by blank lines; print URI SUITE pairs of enabled 'deb' stanzas.
    awk '
      function flush() {
        if (types ~ /(^| )deb( |$)/ && enabled != "no")
          for (u = 1; u <= nu; u++) for (s = 1; s <= ns; s++) print uris[u], suites[s]
        types = ""; enabled = ""; nu = 0; ns = 0
      }
      /^[[:space:]]*#/ { next }
      /^[[:space:]]*$/ { flush(); next }
      tolower($1) == "types:"   { types = ""; for (i = 2; i <= NF; i++) types = types " " $i; types = types " " }
      tolower($1) == "uris:"    { for (i = 2; i <= NF; i++) uris[++nu] = $i }
      tolower($1) == "suites:"  { for (i = 2; i <= NF; i++) suites[++ns] = $i }
      tolower($1) == "enabled:" { enabled = tolower($2) }
      END { flush() }
    ' "$f"
  done
}

entries="$(apt_entries | sed -E 's#/+ # #')"
mirror="${DEBIAN_MIRROR:-$(awk -v s="$suite" '$2 == s {print $1; exit}' <<<"$entries")}"
security_mirror="$(awk -v s="$suite-security" '$2 == s {print $1; exit}' <<<"$entries")"
has_updates="$(awk -v s="$suite-updates" '$2 == s {print "yes"; exit}' <<<"$entries")"
[ -n "$mirror" ] || die 4 "no enabled 'deb ... $suite' entry in /etc/apt/sources.list{,.d/*.list,.d/*.sources}; set DEBIAN_MIRROR=http://your.mirror/debian"
say "mirror $mirror${security_mirror:+, security $security_mirror}"

# --- debootstrap ---------------------------------------------------------------------------
if ! command -v debootstrap >/dev/null; then
  say "installing debootstrap with apt-get"
  command -v apt-get >/dev/null || die 3 "debootstrap is missing and apt-get is not available to install it"
  { $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends debootstrap; } \
    >/tmp/docker-base-image-apt.log 2>&1 ||
    { tail -n 10 /tmp/docker-base-image-apt.log >&2; die 3 "debootstrap is missing and 'apt-get install debootstrap' failed"; }
fi

mkdir -p "$cache_dir"
cache_dir="$(cd "$cache_dir" && pwd)"
rootfs="$cache_dir/rootfs"
stamp="$cache_dir/rootfs.stamp"
stamp_want="suite=$suite mirror=$mirror arch=$(dpkg --print-architecture)"

unmount_all() { # a debootstrap killed by the timeout can leave proc/sys mounted in the target
  local d=$1 m
  [ -d "$d" ] || return 0
  for m in $(awk -v d="$d/" 'index($5, d) == 1 {print $5}' /proc/self/mountinfo | sort -r); do
    $sudo umount -l "$m" 2>/dev/null || true
  done
}

reuse=0
if [ "$force" -eq 0 ] && [ -d "$rootfs" ] && [ -f "$stamp" ] && [ "$(head -1 "$stamp")" = "$stamp_want" ] &&
  [ -n "$(find "$stamp" -mtime "-$max_age_days" 2>/dev/null)" ]; then
  reuse=1
  say "reusing $rootfs (made $(sed -n 2p "$stamp"), younger than $max_age_days days)"
fi

if [ "$reuse" -eq 0 ]; then
  tmp="$cache_dir/rootfs.tmp"
  unmount_all "$tmp"
  $sudo rm -rf "$tmp"
  keyring=/usr/share/keyrings/debian-archive-keyring.gpg
  keyring_opt=()
  [ -f "$keyring" ] && keyring_opt=(--keyring="$keyring")
  say "debootstrap --variant=minbase $suite into $tmp (bounded to ${timeout_s}s; log in $cache_dir/debootstrap.log)"
  start=$(date +%s)
  trap 'unmount_all "$tmp"' EXIT
  if ! $sudo timeout --kill-after=30 "$timeout_s" debootstrap --variant=minbase "${keyring_opt[@]}" \
    "$suite" "$tmp" "$mirror" >"$cache_dir/debootstrap.log" 2>&1; then
    tail -n 15 "$cache_dir/debootstrap.log" >&2
    die 5 "debootstrap failed or exceeded ${timeout_s}s (full log: $cache_dir/debootstrap.log)"
  fi
  say "debootstrap done in $(($(date +%s) - start))s"

  # --- make it an image root: apt sources, Docker-friendly apt/dpkg settings, no caches ----------
  {
    echo "Types: deb"
    echo "URIs: $mirror"
    echo "Suites: $suite${has_updates:+ $suite-updates}"
    echo "Components: main"
    echo "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg"
    if [ -n "$security_mirror" ]; then
      echo
      echo "Types: deb"
      echo "URIs: $security_mirror"
      echo "Suites: $suite-security"
      echo "Components: main"
      echo "Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg"
    fi
  } | $sudo tee "$tmp/etc/apt/sources.list.d/debian.sources" >/dev/null
  $sudo rm -f "$tmp/etc/apt/sources.list"
  # As in Debian's official images (debuerreotype): no services started by package scripts,
  # no package caches or translations kept in layers, no docs/man pages (copyright files stay).
  printf '#!/bin/sh\nexit 101\n' | $sudo tee "$tmp/usr/sbin/policy-rc.d" >/dev/null
  $sudo chmod 755 "$tmp/usr/sbin/policy-rc.d"
  $sudo tee "$tmp/etc/apt/apt.conf.d/docker-clean" >/dev/null <<'EOF'
DPkg::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
APT::Update::Post-Invoke { "rm -f /var/cache/apt/archives/*.deb /var/cache/apt/archives/partial/*.deb /var/cache/apt/*.bin || true"; };
Dir::Cache::pkgcache "";
Dir::Cache::srcpkgcache "";
EOF
  echo 'Acquire::Languages "none";' | $sudo tee "$tmp/etc/apt/apt.conf.d/docker-no-languages" >/dev/null
  echo 'Apt::AutoRemove::SuggestsImportant "false";' | $sudo tee "$tmp/etc/apt/apt.conf.d/docker-autoremove-suggests" >/dev/null
  $sudo tee "$tmp/etc/dpkg/dpkg.cfg.d/docker-slim" >/dev/null <<'EOF'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/locale/*
path-exclude /usr/share/lintian/*
path-exclude /usr/share/linda/*
EOF
  $sudo find "$tmp/usr/share/doc" -mindepth 1 -not -name copyright -not -type d -delete 2>/dev/null || true
  $sudo find "$tmp/usr/share/doc" -mindepth 1 -type d -empty -delete 2>/dev/null || true
  $sudo rm -rf "$tmp"/usr/share/man/* "$tmp"/usr/share/info/* "$tmp"/usr/share/locale/*
  $sudo rm -rf "$tmp"/var/lib/apt/lists/* "$tmp"/var/cache/apt/* "$tmp"/var/cache/debconf/*-old \
    "$tmp"/var/log/* "$tmp"/tmp/* "$tmp"/var/tmp/* "$tmp"/root/.cache
  $sudo mkdir -p "$tmp/var/lib/apt/lists/partial" "$tmp/var/cache/apt/archives/partial"
  : | $sudo tee "$tmp/etc/machine-id" >/dev/null # systemd's convention for "set at first boot"
  $sudo rm -f "$tmp/etc/resolv.conf" "$tmp/etc/hostname" # the engine provides both
  trap - EXIT
  unmount_all "$tmp"

  $sudo rm -rf "$rootfs"
  $sudo mv "$tmp" "$rootfs"
  printf '%s\n%s\n' "$stamp_want" "$(date -u +%Y-%m-%dT%H:%M:%SZ)" >"$stamp"
fi

# --- import ---------------------------------------------------------------------------------
made="$(sed -n 2p "$stamp")"
say "importing $rootfs as $tag ($($sudo du -sh --exclude=./proc --exclude=./sys "$rootfs" 2>/dev/null | cut -f1))"
start=$(date +%s)
# /dev, /proc and /sys are provided by the engine at run time: ship them empty.
if ! $sudo tar --numeric-owner --xattrs -C "$rootfs" \
  --exclude='./dev/*' --exclude='./proc/*' --exclude='./sys/*' -c . |
  docker import \
    --change 'ENV PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'ENV LANG=C.UTF-8' \
    --change 'CMD ["bash"]' \
    --change "LABEL org.opencontainers.image.title=\"Debian $suite minbase (debootstrap)\" org.opencontainers.image.created=\"$made\" org.canfleet.debian-mirror=\"$mirror\"" \
    --message "debootstrap --variant=minbase $suite $mirror ($made)" \
    - "$tag" >/dev/null; then
  die 6 "docker import of $rootfs as $tag failed"
fi
say "imported $tag in $(($(date +%s) - start))s: $(docker image inspect -f '{{.Size}}' "$tag" | awk '{printf "%.1f MB", $1/1e6}')"
