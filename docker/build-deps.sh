#!/usr/bin/env bash
# Build stage of docker/Dockerfile: installs the Debian packages canfleet builds with, taken from
# scripts/install-deps.sh (the one list), minus what only the host's tests need (test VM, fuzzing,
# formatting, Python, can-utils, vcan tools, debootstrap, unit-test frameworks). Falls back to running
# install-deps.sh whole if its list cannot be read.
#   docker/build-deps.sh path/to/install-deps.sh
set -euo pipefail
deps_script=${1:?usage: build-deps.sh path/to/install-deps.sh}

# Not needed to build the shipped binaries (CANFLEET_BUILD_TESTS=OFF, no fuzzing, no VM).
skip=" qemu-system-x86 busybox-static cpio clang libclang-rt-14-dev clang-format python3 python3-venv "
skip+=" can-utils libgtest-dev libgmock-dev libbenchmark-dev git iproute2 xz-utils zstd debootstrap "

packages=()
eval "$(sed -n '/^packages=(/,/^)/p' "$deps_script")" || packages=()
export DEBIAN_FRONTEND=noninteractive
if [ ${#packages[@]} -eq 0 ]; then
  echo "build-deps: could not read the package list of $deps_script: running it whole"
  apt-get update -qq
  exec bash "$deps_script"
fi

wanted=()
for p in "${packages[@]}"; do
  case "$skip" in *" $p "*) ;; *) wanted+=("$p") ;; esac
done
echo "build-deps: ${wanted[*]}"
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${wanted[@]}" >/dev/null
