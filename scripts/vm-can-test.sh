#!/usr/bin/env bash
# Runs a test binary against a real SocketCAN interface (vcan0) inside a throw-away VM.
#
# This machine's kernel (and many CI kernels) has no CAN support, so the SocketCAN code is tested
# in a small VM: a stock Debian kernel (linux-image-*-amd64, downloaded with `apt-get download` and
# unpacked with `dpkg-deb -x` into the cache, so the host is not modified) boots a busybox
# initramfs that loads the CAN modules (can, can-raw, can-gw, can-dev, vcan) and the virtio/9p
# modules, mounts the host's / read-only over 9p, chroots into it, creates vcan0, checks that
# cansend/candump from can-utils see each other, then runs the test binary unchanged.
# The verdict comes back through a second, writable 9p share (a job directory in the cache).
#
#   scripts/vm-can-test.sh [--skip-code N] [--ctest] [--timeout S] <test-binary> [args...]
#
# Exit status: 0 passed; 1 failed; N (default 0) when the VM cannot run here, after printing
# "SKIPPED: <reason>". A skip is never reported as a pass: the last line always counts
# passed/failed/skipped.
# --ctest (how tests/unit/socketcan registers it): skip code 77, which the test's SKIP_RETURN_CODE
# turns into "Skipped"; and, because ctest shows the output of a passed or skipped test nowhere,
# the verdict line is also written to ctest's own output when that is a pipe or a terminal.
#
# Environment:
#   CANFLEET_VM_CACHE       cache folder (default <repo>/build-vm): kernel, busybox, initramfs
#   CANFLEET_VM_ACCEL       auto (default: KVM if it boots within CANFLEET_VM_KVM_PROBE s, else TCG),
#                           kvm or tcg
#   CANFLEET_VM_NO_INSTALL  1: never apt-get install qemu-system-x86 (skip instead)
#   CANFLEET_VM_QEMU        the qemu-system-x86_64 to use (default: the one on PATH)
#   CANFLEET_VM_TIMEOUT     whole-VM time limit in seconds (default 180; --timeout overrides)
set -uo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
cache=${CANFLEET_VM_CACHE:-$repo/build-vm}
accel_mode=${CANFLEET_VM_ACCEL:-auto}
total_timeout=${CANFLEET_VM_TIMEOUT:-180}
kvm_probe_timeout=${CANFLEET_VM_KVM_PROBE:-15}
boot_timeout=${CANFLEET_VM_BOOT_TIMEOUT:-90}
skip_code=0
under_ctest=0
start_time=$(date +%s)

# The modules the guest needs; their dependencies come from the kernel's modules.dep.
wanted_modules=(virtio_pci 9pnet_virtio 9p can can-raw can-gw can-dev vcan)

while [ $# -gt 0 ]; do
  case "$1" in
    --skip-code) skip_code=$2; shift 2 ;;
    --ctest) skip_code=77; under_ctest=1; shift ;;
    --timeout) total_timeout=$2; shift 2 ;;
    -h | --help) awk 'NR > 1 && !/^#/ {exit} NR > 1 {sub(/^# ?/, ""); print}' "$0"; exit 0 ;;
    --) shift; break ;;
    -*) echo "vm-can-test: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
if [ $# -lt 1 ]; then
  echo "usage: $0 [--skip-code N] [--timeout S] <test-binary> [args...]" >&2
  exit 2
fi

log() { echo "vm-can-test: $*"; }
elapsed() { echo $(($(date +%s) - start_time)); }
finish() {  # finish passed|failed|skipped <reason>
  local verdict=$1 reason=$2 p=0 f=0 s=0 line
  case "$verdict" in
    passed) p=1; line="PASSED: $reason ($(elapsed) s)" ;;
    failed) f=1; line="FAILED: $reason ($(elapsed) s)" ;;
    skipped) s=1; line="SKIPPED: $reason" ;;
  esac
  echo "$line"
  if [ "$under_ctest" = 1 ]; then
    local parent_out=/proc/$PPID/fd/1
    if [ "$(cat "/proc/$PPID/comm" 2>/dev/null)" = ctest ] && { [ -p "$parent_out" ] || [ -c "$parent_out" ]; }; then
      echo "      vm-can-test: $line" >>"$parent_out" 2>/dev/null
    fi
  fi
  echo "vm-can-test: $p passed, $f failed, $s skipped"
  case "$verdict" in
    passed) exit 0 ;;
    failed) exit 1 ;;
    skipped) exit "$skip_code" ;;
  esac
}
skip() { finish skipped "$1"; }
fail() { finish failed "$1"; }

test_binary=$1
shift
case "$test_binary" in /*) ;; *) test_binary=$(pwd)/$test_binary ;; esac
[ -x "$test_binary" ] || fail "test binary $test_binary does not exist or is not executable (build it first)"

mkdir -p "$cache" || skip "cannot create the cache folder $cache"
cache=$(cd "$cache" && pwd)

# --- qemu -----------------------------------------------------------------------------------
find_qemu() {
  if [ -n "${CANFLEET_VM_QEMU:-}" ]; then
    [ -x "$CANFLEET_VM_QEMU" ] && echo "$CANFLEET_VM_QEMU"
  else
    command -v qemu-system-x86_64 2>/dev/null
  fi
}
qemu=$(find_qemu)
if [ -z "$qemu" ] && [ -z "${CANFLEET_VM_QEMU:-}" ] && [ "${CANFLEET_VM_NO_INSTALL:-0}" != 1 ] && [ "$(id -u)" -eq 0 ] &&
  command -v apt-get >/dev/null; then
  log "qemu-system-x86_64 missing: apt-get install qemu-system-x86"
  if ! DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends qemu-system-x86 \
    >"$cache/apt-qemu.log" 2>&1; then
    apt-get update -qq >>"$cache/apt-qemu.log" 2>&1 &&
      DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends qemu-system-x86 \
        >>"$cache/apt-qemu.log" 2>&1
  fi
  qemu=$(find_qemu)
fi
[ -n "$qemu" ] || skip "qemu-system-x86_64${CANFLEET_VM_QEMU:+ ($CANFLEET_VM_QEMU)} is not installed and could not be installed (apt-get install qemu-system-x86)"

# --- kernel and busybox, downloaded once into the cache -------------------------------------
# download_deb <package> <dest-dir>: apt-get download + dpkg-deb -x, without touching the host's
# package database.
download_deb() {
  local pkg=$1 dest=$2 tmp
  tmp=$(mktemp -d "$cache/download.XXXXXX")
  if ! (cd "$tmp" && apt-get download "$pkg" >"$cache/apt-download.log" 2>&1); then
    rm -rf "$tmp"
    return 1
  fi
  # Unpacked beside the destination and renamed into place, so a concurrent run never sees half.
  local part=$dest.partial.$$
  rm -rf "$part" && mkdir -p "$part" && dpkg-deb -x "$tmp"/*.deb "$part" &&
    { [ -d "$dest" ] || mv -T "$part" "$dest"; }
  local rc=$?
  rm -rf "$tmp" "$part"
  return $rc
}

command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null ||
  [ -f "$cache/kernel/ready" ] || skip "no apt-get/dpkg-deb to fetch a kernel, and none cached in $cache"

if [ ! -f "$cache/kernel/ready" ]; then
  kpkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
  if [ -z "$kpkg" ]; then
    apt-get update -qq >/dev/null 2>&1
    kpkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ {print $2; exit}')
  fi
  [ -n "$kpkg" ] || skip "no linux-image-*-amd64 kernel package known to apt (apt-cache depends linux-image-amd64)"
  log "downloading kernel package $kpkg (once; cached in $cache/kernel)"
  download_deb "$kpkg" "$cache/kernel" || skip "could not download $kpkg (see $cache/apt-download.log)"
  touch "$cache/kernel/ready"
fi
kernel_image=$(ls "$cache"/kernel/boot/vmlinuz-* 2>/dev/null | head -n 1)
[ -n "$kernel_image" ] || skip "the cached kernel package has no /boot/vmlinuz-*; remove $cache/kernel"
kver=${kernel_image##*/vmlinuz-}
moddir=$cache/kernel/lib/modules/$kver

if [ ! -x "$cache/busybox/bin/busybox" ]; then
  log "downloading busybox-static (once; cached in $cache/busybox)"
  download_deb busybox-static "$cache/busybox" || skip "could not download busybox-static (see $cache/apt-download.log)"
fi
busybox=$cache/busybox/bin/busybox

# modules.dep is written by depmod at install time, not shipped in the package: busybox makes it.
if [ ! -f "$moddir/modules.dep" ]; then
  log "generating modules.dep for $kver"
  "$busybox" depmod -b "$cache/kernel" "$kver" || fail "depmod failed for $kver"
fi

# --- initramfs: busybox + the modules in dependency order + /init -----------------------------
declare -A module_path=() module_deps=() module_seen=()
while IFS= read -r line; do
  path=${line%%:*}
  name=${path##*/}
  name=${name%%.ko*}
  name=${name//-/_}
  module_path[$name]=$path
  module_deps[$name]=${line#*:}
done <"$moddir/modules.dep"

load_order=()
add_module() {  # depth-first: every dependency before the module itself
  local name=${1//-/_} dep
  [ -n "${module_seen[$name]:-}" ] && return 0
  module_seen[$name]=1
  if [ -z "${module_path[$name]:-}" ]; then
    grep -Eq "/${1}\.ko|/${name}\.ko" "$moddir/modules.builtin" && return 0
    fail "kernel $kver has no module $1 (neither in modules.dep nor built in)"
  fi
  for dep in ${module_deps[$name]}; do
    dep=${dep##*/}
    add_module "${dep%%.ko*}"
  done
  load_order+=("${module_path[$name]}")
}
for m in "${wanted_modules[@]}"; do add_module "$m"; done

init_script=$(
  cat <<'EOF'
#!/bin/busybox sh
# canfleet VM init: load modules, mount the host's / (read-only) and the job share, run the job.
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
echo "canfleet-vm: init started ($(uname -r))"
die() {
  echo "canfleet-vm: error: $*"
  sync
  reboot -f
}
while read -r m; do
  insmod "/modules/$m" || die "insmod $m failed"
done </modules/order
echo "canfleet-vm: modules loaded"
mkdir -p /job /newroot
opts=trans=virtio,version=9p2000.L,msize=512000
mount -t 9p -o "$opts" job /job || die "cannot mount the job share"
job_path=$(cat /job/path)
mount -t 9p -o "$opts,ro,cache=loose" hostroot /newroot || die "cannot mount the host root"
mount -t proc proc /newroot/proc || die "cannot mount /proc in the host root"
mount -t sysfs sys /newroot/sys
mount -t devtmpfs dev /newroot/dev
mkdir -p /newroot/dev/pts /newroot/dev/shm 2>/dev/null
mount -t devpts devpts /newroot/dev/pts 2>/dev/null
mount -t tmpfs tmpfs /newroot/dev/shm 2>/dev/null
mount --bind /job "/newroot$job_path" || die "cannot bind the job share on $job_path"
echo "canfleet-vm: running job"
chroot /newroot /bin/sh "$job_path/job.sh"
echo "canfleet-vm: job finished (exit $?)"
sync
umount "/newroot$job_path" 2>/dev/null
umount /job 2>/dev/null
reboot -f
EOF
)

initrd_key=$(printf '%s\n' "$kver" "${load_order[@]}" "$init_script" | sha256sum | cut -c1-16)
initrd=$cache/initramfs-$initrd_key.cpio.gz
if [ ! -f "$initrd" ]; then
  log "building initramfs ${initrd##*/} (${#load_order[@]} modules)"
  root=$(mktemp -d "$cache/initramfs.XXXXXX")
  mkdir -p "$root"/{bin,dev,proc,sys,modules}
  cp "$busybox" "$root/bin/busybox"
  ln -s busybox "$root/bin/sh"
  : >"$root/modules/order"
  for p in "${load_order[@]}"; do
    f=${p##*/}
    case "$f" in
      *.ko.xz) xz -dc "$moddir/$p" >"$root/modules/${f%.xz}" ;;
      *.ko.zst) zstd -qdc "$moddir/$p" >"$root/modules/${f%.zst}" ;;
      *.ko.gz) gzip -dc "$moddir/$p" >"$root/modules/${f%.gz}" ;;
      *) cp "$moddir/$p" "$root/modules/$f" ;;
    esac || fail "cannot unpack module $p"
    echo "${f%.ko*}.ko" >>"$root/modules/order"
  done
  printf '%s\n' "$init_script" >"$root/init"
  chmod +x "$root/init"
  (cd "$root" && find . | "$busybox" cpio -o -H newc 2>/dev/null | gzip -1) >"$initrd.partial.$$" &&
    mv "$initrd.partial.$$" "$initrd" || fail "cannot build the initramfs"
  rm -rf "$root"
fi

# --- the job: what runs inside the chroot ------------------------------------------------------
mkdir -p "$cache/jobs"
job=$(mktemp -d "$cache/jobs/job.XXXXXX")
trap 'rm -rf "$job"' EXIT
mkdir -p "$job/tmp"
printf '%s\n' "$job" >"$job/path"
quoted_cmd=$(printf '%q ' "$test_binary" "$@")
# Sanitizer and GoogleTest settings of the caller reach the test binary in the VM.
forwarded_env=$(env | grep -E '^(ASAN|UBSAN|LSAN|GTEST)_[A-Z_]*=' | while IFS='=' read -r name value; do
  printf 'export %s=%q\n' "$name" "$value"
done)
cat >"$job/job.sh" <<EOF
# Runs inside the VM, chrooted into the host's / (read-only); only $job is writable.
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
export HOME=$job TMPDIR=$job/tmp LANG=C GTEST_COLOR=no CANFLEET_VCAN=vcan0
$forwarded_env
cd $job
result() { echo "\$1" >>$job/result; }
if ip link add dev vcan0 type vcan && ip link set up vcan0; then
  result vcan=ok
else
  echo "canfleet-vm: cannot create vcan0"
  result vcan=failed
  exit 1
fi
if command -v candump >/dev/null && command -v cansend >/dev/null; then
  candump -n 1 -T 5000 vcan0 >$job/candump.txt 2>&1 &
  dump=\$!
  sleep 0.5
  cansend vcan0 123#DEADBEEF
  wait \$dump
  if grep -q "vcan0  123   \\[4\\]  DE AD BE EF" $job/candump.txt; then
    echo "canfleet-vm: can-utils check ok (cansend 123#DEADBEEF seen by candump)"
    result canutils=ok
  else
    echo "canfleet-vm: can-utils check FAILED; candump printed:"
    cat $job/candump.txt
    result canutils=failed
  fi
else
  echo "canfleet-vm: can-utils not installed on the host: cansend/candump check not run"
  result canutils=missing
fi
echo "canfleet-vm: \$ $quoted_cmd"
$quoted_cmd
rc=\$?
result "test_rc=\$rc"
exit \$rc
EOF

# --- boot ----------------------------------------------------------------------------------------
kvm_usable() { [ -r /dev/kvm ] && [ -w /dev/kvm ]; }
kvm_verdict=$cache/kvm-$(uname -r)
case "$accel_mode" in
  kvm) kvm_usable || skip "CANFLEET_VM_ACCEL=kvm but /dev/kvm is not usable"; accels=(kvm) ;;
  tcg) accels=(tcg) ;;
  auto)
    if kvm_usable && [ "$(cat "$kvm_verdict" 2>/dev/null)" != hangs ]; then accels=(kvm tcg); else accels=(tcg); fi
    ;;
  *) fail "CANFLEET_VM_ACCEL must be auto, kvm or tcg (got $accel_mode)" ;;
esac

qemu_pid=""
cleanup_qemu() { [ -n "$qemu_pid" ] && kill "$qemu_pid" 2>/dev/null; }
trap 'cleanup_qemu; rm -rf "$job"' EXIT
trap 'cleanup_qemu; exit 130' INT TERM

# boot <accel> <seconds to see init start>: 0 booted and ran to the end, 2 no boot in time,
# 3 timed out after booting. The time limits are enforced here (not with timeout(1)) and the qemu
# job is disowned, so a qemu that aborts does not make bash print a job report.
boot() {
  local accel=$1 boot_limit=$2 cpu=max console=$job/console-$1.log booted=0 waited=0 t0=$SECONDS
  [ "$accel" = kvm ] && cpu=host
  : >"$console"
  "$qemu" -accel "$accel" -cpu "$cpu" -m 1024 -smp 1 \
    -nodefaults -no-reboot -display none -monitor none -serial "file:$console" \
    -kernel "$kernel_image" -initrd "$initrd" \
    -append "console=ttyS0 loglevel=3 panic=-1 rdinit=/init" \
    -virtfs "local,path=/,mount_tag=hostroot,readonly=on,security_model=none,multidevs=remap" \
    -virtfs "local,path=$job,mount_tag=job,security_model=none" \
    </dev/null >"$job/qemu-$accel.log" 2>&1 &
  qemu_pid=$!
  disown "$qemu_pid"
  tail -n +1 -f --pid="$qemu_pid" "$console" 2>/dev/null | sed -u 's/\r$//; s/^/  vm| /' &
  local tail_pid=$! outcome=0
  while kill -0 "$qemu_pid" 2>/dev/null; do
    if [ $booted = 0 ] && grep -q "canfleet-vm: init started" "$console"; then
      booted=1
      log "guest booted under $accel in ${waited}s"
    fi
    if { [ $booted = 0 ] && [ "$waited" -ge "$boot_limit" ]; } || [ "$waited" -ge "$total_timeout" ]; then
      kill "$qemu_pid" 2>/dev/null
      for _ in 1 2 3 4 5; do kill -0 "$qemu_pid" 2>/dev/null && sleep 1; done
      kill -9 "$qemu_pid" 2>/dev/null
      outcome=3
      break
    fi
    sleep 1
    waited=$((SECONDS - t0))
  done
  qemu_pid=""
  wait "$tail_pid" 2>/dev/null
  if ! grep -q "canfleet-vm: init started" "$console"; then
    [ -s "$job/qemu-$accel.log" ] && sed 's/^/  qemu| /' "$job/qemu-$accel.log"
    if [ $outcome = 3 ]; then boot_note="no boot within ${boot_limit}s"; else boot_note="qemu exited"; fi
    return 2
  fi
  return $outcome
}

verdict=""
boot_note=""
for accel in "${accels[@]}"; do
  limit=$boot_timeout
  [ "$accel" = kvm ] && [ ${#accels[@]} -gt 1 ] && limit=$kvm_probe_timeout
  log "booting $kver under $accel (time limit ${total_timeout}s)"
  boot "$accel" "$limit"
  case $? in
    0) verdict=done; break ;;
    3) verdict=timeout; break ;;
    2)
      if [ "$accel" = kvm ] && [ ${#accels[@]} -gt 1 ]; then
        log "KVM did not boot the guest ($boot_note): falling back to TCG (remembered in $kvm_verdict)"
        echo hangs >"$kvm_verdict"
        rm -f "$job/result"
        continue
      fi
      verdict=noboot
      ;;
  esac
done
[ "$accel" = kvm ] && [ "$verdict" = done ] && echo works >"$kvm_verdict"

console=$job/console-$accel.log
qemu_said=""
[ "$boot_note" = "qemu exited" ] && qemu_said=$(tail -n 1 "$job/qemu-$accel.log" 2>/dev/null)
case "$verdict" in
  noboot)
    if [ -s "$console" ]; then
      fail "the guest kernel started but /init never ran under $accel (console above)"
    fi
    skip "the VM did not boot under $accel: $boot_note (qemu too slow here or unable to run${qemu_said:+: $qemu_said})"
    ;;
  timeout) fail "the VM did not finish within ${total_timeout}s" ;;
esac
grep -q "canfleet-vm: error:" "$console" && fail "$(grep -m1 'canfleet-vm: error:' "$console" | sed 's/.*error: //')"
[ -f "$job/result" ] || fail "the VM stopped without a result"
grep -qx vcan=ok "$job/result" || fail "could not create vcan0 in the VM"
grep -qx canutils=failed "$job/result" && fail "cansend/candump check failed in the VM"
test_rc=$(sed -n 's/^test_rc=//p' "$job/result")
[ -n "$test_rc" ] || fail "the test binary did not finish in the VM"
[ "$test_rc" = 0 ] || fail "${test_binary##*/} exited with $test_rc in the VM"
finish passed "${test_binary##*/} on vcan0 in a $kver VM under $accel"
