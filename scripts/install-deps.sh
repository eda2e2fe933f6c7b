#!/usr/bin/env bash
# Installs the Debian 12 packages canfleet builds and tests with. Idempotent: does nothing when
# everything is already installed.
#
#   scripts/install-deps.sh           install what is missing
#   scripts/install-deps.sh --check   install nothing; check that every program in `programs` below
#                                     is on PATH (exit 1 naming the missing ones and their packages)
#
# One rule: every external program a script, test or build step calls comes from a package in
# `packages`, and is listed in `programs` with that package. tests/docker/run.sh runs this script in
# a fresh container of the project's base image and then --check, so a program that only the
# developers' machines happen to have fails CI instead of a user's first run.
set -euo pipefail

packages=(
  build-essential cmake ninja-build ccache pkg-config git
  libasio-dev libspdlog-dev libfmt-dev libcli11-dev zlib1g-dev libboost-dev
  libprotobuf-dev protobuf-compiler
  cyclonedds-dev cyclonedds-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev clang-format
  python3 python3-venv can-utils jq
  qemu-system-x86 busybox-static cpio iproute2 xz-utils zstd
  tshark
  debootstrap
  chromium
)

# program:package — who calls it
programs=(
  cmake:cmake ninja:ninja-build ccache:ccache pkg-config:pkg-config git:git # build (scripts/test.sh)
  c++:build-essential cc:build-essential                                   # the default toolchain
  protoc:protobuf-compiler idlc:cyclonedds-tools                           # generated code (CMake; python/setup.py)
  clang:clang clang++:clang clang-format:clang-format                      # scripts/fuzz.sh, formatting
  python3:python3                                                          # scripts, conformance, fuzz.sh
  candump:can-utils cansend:can-utils log2long:can-utils                   # capture and vcan tests
  tshark:tshark                                                            # capture dissector test
  jq:jq                                                                    # README examples (tests/docs)
  ip:iproute2                                                              # vcan tests (ip link add ... type vcan)
  qemu-system-x86_64:qemu-system-x86 busybox:busybox-static cpio:cpio      # scripts/vm-can-test.sh
  xz:xz-utils zstd:zstd gzip:gzip                                          # vm-can-test.sh: kernel modules, initramfs
  apt-get:apt apt-cache:apt dpkg-deb:dpkg                                  # vm-can-test.sh: kernel download
  debootstrap:debootstrap                                                  # scripts/docker-base-image.sh
  chromium:chromium                                                        # tests/system/web: the page in a browser
  timeout:coreutils sha256sum:coreutils mktemp:coreutils awk:mawk sed:sed find:findutils tar:tar flock:util-linux
)

if [ "${1:-}" = "--check" ]; then
  missing=()
  for entry in "${programs[@]}"; do
    command -v "${entry%%:*}" >/dev/null || missing+=("${entry%%:*} (package ${entry#*:})")
  done
  # python3-venv: scripts/python-env.sh makes the project's venv with `python3 -m venv`.
  python3 -c 'import ensurepip, venv' 2>/dev/null || missing+=("python3 -m venv (package python3-venv)")
  if [ ${#missing[@]} -gt 0 ]; then
    printf 'install-deps: missing: %s\n' "${missing[@]}" >&2
    exit 1
  fi
  echo "install-deps: all ${#programs[@]} programs present"
  exit 0
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
echo "install-deps: installing ${missing[*]}"
# tshark asks whether non-root users may capture; answer no so the install never prompts.
echo "wireshark-common wireshark-common/install-setuid boolean false" | $sudo debconf-set-selections
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
