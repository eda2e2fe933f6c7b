#!/usr/bin/env bash
# Build stage of docker/Dockerfile: builds the shipped executables and stages what the runtime
# image holds under OUT:
#   OUT/bin/                    every executable named `canfleet` or `canfleet-*` (stripped)
#   OUT/share/canfleet/         topologies/, devices/<variant>/<variant>.eds (canfleet-node --write-eds), telemetry/*.xml,
#                               web/ (canfleet web's page)
#   OUT/etc/canfleet/           telemetry/*.xml again (the Cyclone DDS configs)
#   OUT/runtime-packages.txt    the Debian packages owning the shared libraries they link
# Shipped executables follow the naming convention `canfleet[-<name>]` (tests and benchmarks use
# underscores), so new ones are picked up without editing this file. If the project defines
# install() rules, `cmake --install` is used as well.
#   docker/stage.sh SRC BUILD OUT
# CANFLEET_KEEP_GOING=1: ship the executables that build and only warn about the others (for
# imaging an in-progress tree; off by default: a broken tree fails the image build).
set -euo pipefail
src=${1:?usage: stage.sh SRC BUILD OUT} build=${2:?} out=${3:?}
mkdir -p "$out/bin" "$out/share/canfleet" "$out/etc/canfleet"
jobs=${CANFLEET_JOBS:-$(nproc)}

if grep -rqs --include=cmake_install.cmake 'file(INSTALL' "$build"; then
  echo "stage: the project has install() rules: building all, then cmake --install"
  cmake --build "$build" -j "$jobs"
  cmake --install "$build" --prefix "$out/install" --strip
  find "$out/install/bin" -type f -perm -u+x -exec cp -a {} "$out/bin/" \; 2>/dev/null || true
else
  # Executable targets from Ninja's rule names (CXX_EXECUTABLE_LINKER__<target>_<config>).
  mapfile -t targets < <(ninja -C "$build" -t targets all |
    sed -nE 's/.*: (C|CXX)_EXECUTABLE_LINKER__(canfleet(-[A-Za-z0-9-]+)?)_[A-Za-z]+$/\2/p' | sort -u)
  if [ ${#targets[@]} -eq 0 ]; then
    echo "stage: WARNING: the tree defines no executable named canfleet or canfleet-*: the image ships none"
  else
    echo "stage: building ${targets[*]}"
    if [ "${CANFLEET_KEEP_GOING:-0}" = 1 ]; then
      # An in-progress tree: ship whatever compiles (ninja -k 0), say what did not.
      cmake --build "$build" -j "$jobs" --target "${targets[@]}" -- -k 0 >"$build/stage-build.log" 2>&1 ||
        { grep -E 'error:|FAILED:' "$build/stage-build.log" | head -20
          echo "stage: WARNING: some targets failed to build (CANFLEET_KEEP_GOING=1): shipping the ones that built"; }
    else
      cmake --build "$build" -j "$jobs" --target "${targets[@]}"
    fi
    for t in "${targets[@]}"; do
      find "$build" -type f -name "$t" -perm -u+x -exec cp {} "$out/bin/" \;
    done
    strip --strip-unneeded "$out"/bin/* 2>/dev/null || true
  fi
fi

# Shipped data (whatever exists yet).
share="$out/share/canfleet"
if [ -d "$src/topologies" ]; then
  mkdir -p "$share/topologies"
  (cd "$src/topologies" && find . -type f ! -name 'README*' ! -name 'CMakeLists.txt' -exec cp --parents {} "$share/topologies/" \;)
fi
# Each variant's EDS, exactly the one its node runs on (generated from its dictionary table).
if [ -x "$out/bin/canfleet-node" ]; then
  for variant in $("$out/bin/canfleet-node" --list-devices | awk '{print $1}'); do
    mkdir -p "$share/devices/$variant"
    "$out/bin/canfleet-node" --device "$variant" --write-eds "$share/devices/$variant/$variant.eds"
  done
fi
# canfleet web's page (web/static), found beside the binary (web/run_web.cpp StaticDir).
if [ -d "$src/web/static" ]; then
  mkdir -p "$share/web" && cp "$src"/web/static/* "$share/web/"
fi
if compgen -G "$src/telemetry/*.xml" >/dev/null; then
  mkdir -p "$share/telemetry" && cp "$src"/telemetry/*.xml "$share/telemetry/" && cp "$src"/telemetry/*.xml "$out/etc/canfleet/"
fi

# Runtime packages: the owner of every shared library the binaries load.
: >"$out/runtime-packages.txt"
for b in "$out"/bin/*; do
  [ -f "$b" ] || continue
  ldd "$b" | awk '$2 == "=>" && $3 ~ /^\// {print $3} $1 ~ /^\// {print $1}'
done | sort -u | while read -r lib; do
  real=$(readlink -f "$lib")
  for f in "$lib" "$real" "${lib#/usr}" "${real#/usr}" "/usr$lib" "/usr$real"; do
    pkg=$(dpkg-query -S "$f" 2>/dev/null | head -1 | cut -d: -f1) && [ -n "$pkg" ] && { echo "$pkg"; break; }
  done
done | sort -u >"$out/runtime-packages.txt"

echo "stage: binaries: $(cd "$out/bin" && ls | tr '\n' ' ')"
echo "stage: data: $(cd "$share" && find . -type f | sed 's#^\./##' | tr '\n' ' ')"
echo "stage: runtime packages: $(tr '\n' ' ' <"$out/runtime-packages.txt")"
