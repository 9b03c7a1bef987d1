#!/usr/bin/env bash
# vm_run.sh PAYLOAD_DIR SCRIPT [OUT_DIR]
#
# Runs SCRIPT (a path relative to PAYLOAD_DIR) as root with /bin/sh, cwd = a copy of
# PAYLOAD_DIR, on a machine where vcan0 exists as a CAN FD capable (mtu 72) virtual CAN
# interface. The files the script writes to out/ are copied to OUT_DIR (default:
# PAYLOAD_DIR/out). The exit status is the script's; its stdout and stderr appear on
# stdout.
#
# If this machine can create a vcan link (root and a kernel with vcan), the script runs
# directly here ("direct mode"). Otherwise (or with JG_VM_FORCE=1) it runs inside a small
# qemu x86_64 VM (TCG, no KVM needed) booted from Debian's own kernel package, with
# busybox, iproute2's ip and can-utils in the initramfs; /bin/sh there is the host's
# /bin/sh (dash), as in direct mode. Dynamically linked executables in PAYLOAD_DIR get
# their shared library closure copied in at the same absolute paths.
#
#   vm_run.sh --prepare   only download and cache the kernel (see JG_VM_CACHE)
#   vm_run.sh --help
#
# Environment (see tests/vcan/README.md):
#   JG_VM_TIMEOUT=300          kill qemu (boot + script) or the direct-mode script
#                              after this many seconds
#   JG_VM_SCRIPT_TIMEOUT       in-VM limit for the script (default JG_VM_TIMEOUT-60 when
#                              that is >= 30, else none), so out/ still comes back
#   JG_VM_FORCE=1              use the VM even if this machine has vcan
#   JG_VM_CACHE                kernel cache (${XDG_CACHE_HOME:-$HOME/.cache}/jointguard-vm)
#   JG_VM_KERNEL_PKG           Debian kernel package (default: what linux-image-amd64
#                              depends on)
#   JG_VM_MEM=512              VM memory in MiB (the payload lives in RAM)
#   JG_VM_SMP=1                VM CPUs
#   JG_VM_EXTRA_MODULES        further modules to load, e.g. "can-isotp can-bcm"
#   JG_VM_EXTRA_FILES          further host files copied to the same path in the VM (with
#                              their library closure), e.g. a dlopen()ed library
#   JG_VM_VERBOSE=1            kernel messages and progress on the console
#   JG_VM_KEEP=1               keep the work directory (initramfs, logs) for debugging
#
# Exit status: the script's; 77 with "vm_run: SKIP: ..." when no VM can be provided (tool
# missing, kernel download failed); 124 when the timeout killed the VM; 125 for other
# errors of the runner or the VM (messages start with "vm_run: ERROR:").
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

die() {
  echo "vm_run: ERROR: $*" >&2
  exit 125
}
skip() {
  echo "vm_run: SKIP: $*" >&2
  exit 77
}
note() { echo "vm_run: $*" >&2; }
usage() { sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "${BASH_SOURCE[0]}"; }

timeout_s=${JG_VM_TIMEOUT:-300}
[[ $timeout_s =~ ^[0-9]+$ && $timeout_s -gt 0 ]] || die "JG_VM_TIMEOUT must be a positive number of seconds, got '$timeout_s'"
mem=${JG_VM_MEM:-512}
smp=${JG_VM_SMP:-1}
[[ $mem =~ ^[0-9]+$ && $smp =~ ^[0-9]+$ ]] || die "JG_VM_MEM and JG_VM_SMP must be numbers"
if [[ -n ${JG_VM_SCRIPT_TIMEOUT:-} ]]; then
  script_timeout=$JG_VM_SCRIPT_TIMEOUT
  [[ $script_timeout =~ ^[0-9]+$ ]] || die "JG_VM_SCRIPT_TIMEOUT must be a number of seconds"
elif ((timeout_s - 60 >= 30)); then
  script_timeout=$((timeout_s - 60))
else
  script_timeout=0
fi
home=${HOME:-}
[[ -n $home ]] || home=$(getent passwd "$(id -u)" | cut -d: -f6 || true)
[[ -n $home ]] || home=/tmp
cache=${JG_VM_CACHE:-${XDG_CACHE_HOME:-$home/.cache}/jointguard-vm}
verbose=${JG_VM_VERBOSE:-0}

# Cleanup: whatever happens, no qemu (or direct-mode script) keeps running and the work
# directory goes away.
work=""
child_pid=""
reader_pid=""
vcan_created=0
dl_tmp=""
# shellcheck disable=SC2317  # invoked by the EXIT trap
cleanup() {
  local rc=$?
  trap - EXIT INT TERM HUP
  if [[ -n $child_pid ]] && kill -0 "$child_pid" 2>/dev/null; then
    # child_pid is timeout(1); it passes TERM on to qemu / the script.
    kill -TERM "$child_pid" 2>/dev/null || true
    for _ in 1 2 3 4 5 6 7 8 9 10; do
      kill -0 "$child_pid" 2>/dev/null || break
      sleep 0.5
    done
    kill -KILL "$child_pid" 2>/dev/null || true
    [[ -z ${qemu_pid_file:-} || ! -s $qemu_pid_file ]] || kill -KILL "$(cat "$qemu_pid_file")" 2>/dev/null || true
  fi
  if [[ -n $reader_pid ]]; then kill "$reader_pid" 2>/dev/null || true; fi
  if ((vcan_created)); then "$(find_tool ip)" link del dev vcan0 2>/dev/null || true; fi
  if [[ -n $dl_tmp ]]; then rm -rf -- "$dl_tmp"; fi
  if [[ -n $work && -d $work ]]; then
    if [[ ${JG_VM_KEEP:-0} == 1 ]]; then
      note "work directory kept: $work"
    else
      rm -rf -- "$work"
    fi
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
trap 'exit 129' HUP

need() {
  local t
  for t in "$@"; do
    command -v "$t" >/dev/null 2>&1 || skip "'$t' not found (bash scripts/deps.sh installs the VM test tools)"
  done
}
# A host tool that may live in sbin (not on a non-root PATH).
find_tool() {
  local t=$1 d
  if command -v "$t" >/dev/null 2>&1; then command -v "$t"; return 0; fi
  for d in /usr/sbin /sbin; do
    if [[ -x $d/$t ]]; then echo "$d/$t"; return 0; fi
  done
  return 1
}

# ---------------------------------------------------------------------------------------
# Kernel: vmlinuz + the CAN modules from Debian's linux-image package, cached.
kernel_dir=""
ensure_kernel() {
  fetch_kernel
  ensure_vmlinux
}
# Offline: fall back to the newest kernel already in the cache.
use_cached_kernel() {
  local cached
  [[ -z ${JG_VM_KERNEL_PKG:-} ]] || return 1
  cached=$(find "$cache" -mindepth 2 -maxdepth 2 -name .complete -printf '%h\n' 2>/dev/null | sort -V | tail -n 1)
  [[ -n $cached ]] || return 1
  kernel_dir=$cached
  note "$1; using the cached $(basename "$cached")"
}
fetch_kernel() {
  local pkg=${JG_VM_KERNEL_PKG:-}
  mkdir -p -- "$cache" || skip "cannot create the kernel cache directory $cache"
  # The answer of apt-cache (about 1 s) is kept until apt-get update changes the lists.
  local resolved=$cache/.linux-image-amd64 lists=/var/lib/apt/lists
  if [[ -z $pkg && -s $resolved && (! -d $lists || $resolved -nt $lists) ]]; then
    pkg=$(<"$resolved")
  fi
  if [[ -z $pkg ]]; then
    if command -v apt-cache >/dev/null 2>&1; then
      pkg=$(apt-cache depends linux-image-amd64 2>/dev/null |
        sed -n 's/^[ |]*Depends: \(linux-image-[0-9][^ ]*-amd64\)$/\1/p' | sed -n 1p || true)
    fi
    [[ -z $pkg ]] || echo "$pkg" >"$resolved" 2>/dev/null || true
    if [[ -z $pkg ]]; then
      use_cached_kernel "apt-cache cannot resolve linux-image-amd64" && return 0
      skip "cannot determine the Debian kernel package ('apt-cache depends linux-image-amd64' gave nothing; run apt-get update, or set JG_VM_KERNEL_PKG)"
    fi
  fi
  [[ $pkg =~ ^[A-Za-z0-9][A-Za-z0-9.+-]*$ ]] || die "unexpected kernel package name '$pkg'"
  kernel_dir=$cache/$pkg
  [[ -f $kernel_dir/.complete ]] && return 0

  need apt-get dpkg-deb tar
  # One download at a time (parallel ctest runs share the cache).
  exec 9>"$cache/.lock"
  if command -v flock >/dev/null 2>&1; then flock -w 900 9 || die "timed out waiting for the lock $cache/.lock"; fi
  if [[ -f $kernel_dir/.complete ]]; then exec 9>&-; return 0; fi

  local t0 dl ex kver f
  t0=$(date +%s)
  note "downloading the kernel package $pkg into $cache (first run only)"
  dl=$(mktemp -d "$cache/.dl.XXXXXX")
  dl_tmp=$dl
  local apt_opts=(-q)
  [[ $(id -u) -ne 0 ]] || apt_opts+=(-o APT::Sandbox::User=root)
  if ! (cd "$dl" && apt-get "${apt_opts[@]}" download "$pkg") >"$dl/apt.log" 2>&1; then
    sed 's/^/  apt-get: /' "$dl/apt.log" >&2
    rm -rf -- "$dl"
    exec 9>&-
    use_cached_kernel "downloading $pkg failed" && return 0
    skip "kernel download failed: 'apt-get download $pkg' did not work (no network or stale apt lists? run apt-get update)"
  fi
  ex=$dl/x
  mkdir -p "$ex"
  # Only the kernel image, the CAN stack and the CAN drivers (a few MB instead of ~400 MB).
  dpkg-deb --fsys-tarfile "$dl"/*.deb |
    tar -x -C "$ex" --wildcards './boot/vmlinuz-*' './lib/modules/*/modules.builtin' \
      './lib/modules/*/kernel/net/can/*' './lib/modules/*/kernel/drivers/net/can/*' ||
    die "cannot extract the kernel and the CAN modules from $(basename "$dl"/*.deb)"
  f=$(find "$ex/boot" -name 'vmlinuz-*' | head -n 1)
  [[ -n $f ]] || die "no /boot/vmlinuz-* in $pkg"
  kver=${f##*/vmlinuz-}
  mkdir -p "$dl/k/modules"
  mv "$f" "$dl/k/vmlinuz"
  echo "$kver" >"$dl/k/kver"
  [[ ! -f $ex/lib/modules/$kver/modules.builtin ]] || mv "$ex/lib/modules/$kver/modules.builtin" "$dl/k/"
  if [[ -d $ex/lib/modules/$kver/kernel ]]; then
    mv "$ex/lib/modules/$kver/kernel" "$dl/k/modules/kernel"
  fi
  # Newer Debian kernels compress their modules.
  while IFS= read -r -d '' f; do
    case $f in
      *.ko.xz) need xz; xz -d -- "$f" ;;
      *.ko.zst) need zstd; zstd -q -d --rm -- "$f" ;;
      *.ko.gz) gzip -d -- "$f" ;;
    esac
  done < <(find "$dl/k/modules" -name '*.ko.*' -print0)
  touch "$dl/k/.complete"
  rm -rf -- "$kernel_dir"
  mv -T "$dl/k" "$kernel_dir"
  rm -rf -- "$dl"
  dl_tmp=""
  exec 9>&-
  note "kernel $kver cached in $kernel_dir ($(($(date +%s) - t0)) s)"
}

# The uncompressed vmlinux boots in about half the time of vmlinuz under TCG (qemu enters it
# through its PVH note: no real-mode setup and no in-guest decompression of ~60 MB). It is
# unpacked from vmlinuz once and cached next to it; run_vm falls back to vmlinuz.
ensure_vmlinux() {
  [[ ! -f $kernel_dir/vmlinux && ! -f $kernel_dir/.no-vmlinux ]] || return 0
  local tmp off magic tool
  tmp=$(mktemp "$kernel_dir/.vmlinux.XXXXXX" 2>/dev/null) || return 0
  for magic in xz zstd gzip; do
    case $magic in
      xz) tool=(xz -dc --single-stream) ;;
      zstd) tool=(zstd -dcq) ;;
      gzip) tool=(gzip -dc) ;;
    esac
    command -v "${tool[0]}" >/dev/null 2>&1 || continue
    while IFS= read -r off; do
      tail -c "+$((off + 1))" -- "$kernel_dir/vmlinuz" | "${tool[@]}" >"$tmp" 2>/dev/null || true
      if is_elf "$tmp" && [[ $(stat -c %s -- "$tmp") -gt 1000000 ]]; then
        chmod 0644 "$tmp"
        mv -f -- "$tmp" "$kernel_dir/vmlinux"
        return 0
      fi
    done < <(case $magic in
      xz) LC_ALL=C grep -abo $'\xfd7zXZ' -- "$kernel_dir/vmlinuz" ;;
      zstd) LC_ALL=C grep -abo $'\x28\xb5\x2f\xfd' -- "$kernel_dir/vmlinuz" ;;
      gzip) LC_ALL=C grep -abo $'\x1f\x8b\x08' -- "$kernel_dir/vmlinuz" ;;
    esac | cut -d: -f1 | head -n 5)
  done
  rm -f -- "$tmp"
  touch "$kernel_dir/.no-vmlinux"
  note "cannot unpack vmlinux from vmlinuz; booting the compressed kernel (slower)"
}

# Modules to load, in dependency order (read from each module's modinfo "depends=").
declare -A mod_path=() mod_seen=()
mod_order=()
index_modules() {
  local f n
  while IFS= read -r -d '' f; do
    n=${f##*/}
    n=${n%.ko}
    mod_path[${n//-/_}]=$f
  done < <(find "$kernel_dir/modules" -name '*.ko' -print0)
}
add_module() {
  local n=${1//-/_} f deps d
  [[ -z ${mod_seen[$n]:-} ]] || return 0
  mod_seen[$n]=1
  f=${mod_path[$n]:-}
  if [[ -z $f ]]; then
    # Built into the kernel: nothing to load.
    if [[ -f $kernel_dir/modules.builtin ]] && grep -Eq "/${1//[-_]/[-_]}\.ko$" "$kernel_dir/modules.builtin"; then
      return 0
    fi
    die "kernel module '$1' is not among the cached CAN modules of $(basename "$kernel_dir")"
  fi
  deps=$(tr '\0' '\n' <"$f" | sed -n 's/^depends=//p')
  for d in ${deps//,/ }; do add_module "$d"; done
  mod_order+=("${f#"$kernel_dir/modules/"}")
}

# ---------------------------------------------------------------------------------------
# Initramfs.
root=""
is_elf() {
  [[ -f $1 && -r $1 ]] || return 1
  [[ $(head -c 4 -- "$1" | od -An -tx1 | tr -d ' \n') == 7f454c46 ]]
}
# Copy a host file to the same absolute path in the initramfs.
put_host_file() {
  local src=$1 dst=$root$1
  [[ -e $dst ]] && return 0
  mkdir -p -- "$(dirname -- "$dst")"
  cp -L -- "$src" "$dst"
}
# ELF files whose shared library closure goes into the initramfs (see put_closures).
elf_queue=()
put_closure() { elf_queue+=("$1"); }
# One ldd over all queued files; static and foreign-arch ELFs have no closure.
put_closures() {
  ((${#elf_queue[@]})) || return 0
  local out kind a b
  out=$(LC_ALL=C ldd -- "${elf_queue[@]}" 2>/dev/null || true)
  if ((${#elf_queue[@]} == 1)); then out="${elf_queue[0]}:"$'\n'"$out"; fi
  while IFS=$'\t' read -r kind a b; do
    case $kind in
      missing) note "warning: ${a#"$root"} needs $b, which ldd does not find here; it will not run in the VM" ;;
      lib)
        [[ -e $b ]] || die "$a: library $b (from ldd) does not exist"
        put_host_file "$b"
        ;;
    esac
  done < <(awk '/^[^\t ].*:$/ {file = substr($0, 1, length($0) - 1); next}
                $2 == "=>" && $3 == "not" {print "missing\t" file "\t" $1; next}
                $2 == "=>" && $3 ~ /^\// {print "lib\t" file "\t" $3; next}
                $1 ~ /^\// {print "lib\t" file "\t" $1}' <<<"$out")
  elf_queue=()
}
put_tool() {
  put_host_file "$1"
  put_closure "$1"
  echo "$1" >>"$root/etc/jg/tools"
}

build_initramfs() {
  local payload=$1 script=$2 d bb tool f

  root=$work/root
  mkdir -p "$root"
  # Same /usr merge layout as the host, so library paths from ldd resolve either way.
  for d in bin sbin lib lib64; do
    if [[ -L /$d && $(readlink "/$d") == "usr/$d" ]]; then
      mkdir -p "$root/usr/$d"
      ln -s "usr/$d" "$root/$d"
    else
      mkdir -p "$root/$d"
    fi
  done
  mkdir -p "$root"/{usr/bin,usr/sbin,usr/local/bin,proc,sys,dev,tmp,run,root,etc/jg,lib/modules/jg,payload}

  # busybox; the init links its applets (busybox --install -s) in the guest.
  bb=$(find_tool busybox) || skip "busybox not found (apt-get install busybox-static)"
  cp -L -- "$bb" "$root/bin/busybox"
  put_closure "$bb"
  # The script's /bin/sh is the host's (dash on Debian), as in direct mode: Debian's static
  # busybox sh runs its own applets before PATH, so scripts would get busybox's ip.
  f=$(readlink -f /bin/sh || true)
  if [[ -n $f && -x $f ]] && is_elf "$f" && [[ $f != "$(readlink -f -- "$bb")" ]]; then
    put_host_file "$f"
    put_closure "$f"
    ln -s "$f" "$root/bin/sh"
  else
    ln -s /bin/busybox "$root/bin/sh"
  fi

  # Real tools at their host paths; the init links them into /usr/local/bin, first on PATH,
  # ahead of busybox applets of the same name (ip).
  : >"$root/etc/jg/tools"
  for tool in ip candump cansend canplayer cangen; do
    f=$(find_tool "$tool") || skip "'$tool' not found (apt-get install iproute2 can-utils)"
    f=$(readlink -f -- "$f")
    put_tool "$f"
    [[ $tool != ip ]] || echo "$f" >"$root/etc/jg/ip"
  done
  # The rest of can-utils (isotp*, cangw, canbusload, ...) when dpkg knows the package.
  if command -v dpkg-query >/dev/null 2>&1; then
    while IFS= read -r f; do
      [[ $f == /usr/bin/* && -f $f && -x $f ]] || continue
      [[ -e $root$f ]] || put_tool "$f"
    done < <(dpkg-query -L can-utils 2>/dev/null || true)
  fi
  for f in ${JG_VM_EXTRA_FILES:-}; do
    [[ -e $f ]] || die "JG_VM_EXTRA_FILES: $f does not exist"
    put_host_file "$f"
    if is_elf "$f"; then put_closure "$f"; fi
  done

  # Kernel modules.
  index_modules
  local m
  for m in can can-raw can-dev vcan ${JG_VM_EXTRA_MODULES:-}; do add_module "$m"; done
  : >"$root/etc/jg/modules"
  for m in "${mod_order[@]}"; do
    mkdir -p -- "$root/lib/modules/jg/$(dirname -- "$m")"
    cp -- "$kernel_dir/modules/$m" "$root/lib/modules/jg/$m"
    echo "$m" >>"$root/etc/jg/modules"
  done

  # Payload, its executables' libraries, the init and its settings.
  cp -RL --preserve=mode,timestamps -- "$payload/." "$root/payload/"
  rm -rf -- "$root/payload/out"
  mkdir -p "$root/payload/out"
  while IFS= read -r -d '' f; do
    if is_elf "$f"; then put_closure "$f"; fi
  done < <(find "$root/payload" -type f -print0)
  put_closures
  cp -- "$here/guest_init.sh" "$root/init"
  chmod 0755 "$root/init"
  printf '%s\n' "$script" >"$root/etc/jg/script"
  echo "$script_timeout" >"$root/etc/jg/script_timeout"
  echo "$verbose" >"$root/etc/jg/verbose"
  printf 'root:x:0:0:root:/root:/bin/sh\n' >"$root/etc/passwd"
  printf 'root:x:0:\n' >"$root/etc/group"

  (cd "$root" && find . -print0 | LC_ALL=C sort -z | cpio --null -o -H newc -R 0:0 --quiet) |
    gzip -1 >"$work/initramfs.gz"
}

# ---------------------------------------------------------------------------------------
run_vm() {
  local payload=$1 script=$2 out=$3 qemu cmdline rc=0 t0 tq t1 status

  need cpio gzip ldd od sed awk timeout
  qemu=$(find_tool qemu-system-x86_64) || skip "qemu-system-x86_64 not found (apt-get install qemu-system-x86)"
  ensure_kernel
  [[ -f $kernel_dir/vmlinuz ]] || die "no vmlinuz in $kernel_dir (delete that directory to download again)"

  t0=$(date +%s.%N)
  build_initramfs "$payload" "$script"
  tq=$(date +%s.%N)

  cmdline="console=ttyS0 panic=-1 oops=panic rdinit=/init mitigations=off"
  if [[ $verbose == 1 ]]; then cmdline+=" loglevel=6"; else cmdline+=" quiet loglevel=3"; fi

  # ttyS0 (console) goes through a FIFO to our stdout as it happens; ttyS1 (results) to a
  # file. fd 3 keeps the FIFO open until qemu is gone, so the reader never blocks on a qemu
  # that failed to start and never sees EOF before qemu has opened it.
  local fifo=$work/console.fifo xfer=$work/xfer.log
  qemu_pid_file=$work/qemu.pid
  mkfifo "$fifo"
  exec 3<>"$fifo"
  sed -u -e 's/\r$//' -e '/^\[ *[0-9.]*\] reboot: Power down$/d' <"$fifo" 3>&- &
  reader_pid=$!
  local kernel=$kernel_dir/vmlinuz
  [[ ! -f $kernel_dir/vmlinux ]] || kernel=$kernel_dir/vmlinux
  while :; do
    : >"$xfer"
    timeout -k 10 "$timeout_s" "$qemu" \
      -accel tcg -cpu max -m "$mem" -smp "$smp" \
      -nodefaults -no-user-config -display none -no-reboot \
      -pidfile "$qemu_pid_file" \
      -kernel "$kernel" -initrd "$work/initramfs.gz" -append "$cmdline" \
      -chardev "file,id=con,path=${fifo//,/,,}" -serial chardev:con \
      -chardev "file,id=xfer,path=${xfer//,/,,}" -serial chardev:xfer \
      </dev/null >"$work/qemu.log" 2>&1 3>&- &
    child_pid=$!
    rc=0
    wait "$child_pid" || rc=$?
    child_pid=""
    # A vmlinux without a PVH entry: remember that and boot the compressed kernel.
    if ((rc == 1)) && [[ $kernel == */vmlinux ]] && grep -q 'PVH' "$work/qemu.log"; then
      note "this vmlinux has no PVH entry point; using vmlinuz from now on"
      rm -f -- "$kernel_dir/vmlinux"
      touch "$kernel_dir/.no-vmlinux"
      kernel=$kernel_dir/vmlinuz
      continue
    fi
    break
  done
  exec 3>&-
  wait "$reader_pid" || true
  reader_pid=""
  t1=$(date +%s.%N)

  if ((rc == 124 || rc == 137)); then
    echo "vm_run: ERROR: the VM did not finish within ${timeout_s}s (JG_VM_TIMEOUT) and was killed" >&2
    exit 124
  fi
  if ((rc != 0)); then
    sed 's/^/  qemu: /' "$work/qemu.log" >&2
    die "qemu failed (exit status $rc)"
  fi
  tr -d '\r' <"$xfer" >"$work/xfer.txt" 2>/dev/null || : >"$work/xfer.txt"
  if grep -qx '===JG-SETUP-FAILED===' "$work/xfer.txt"; then
    die "the VM could not set up vcan0 (see the console output above)"
  fi
  status=$(sed -n 's/^===JG-EXIT \([0-9]\{1,3\}\)===$/\1/p' "$work/xfer.txt" | tail -n 1)
  if [[ -z $status ]]; then
    [[ ! -s $work/qemu.log ]] || sed 's/^/  qemu: /' "$work/qemu.log" >&2
    die "the VM stopped without reporting the script's exit status (kernel panic, out of memory (JG_VM_MEM=$mem)?); the console output is above, JG_VM_VERBOSE=1 shows kernel messages"
  fi
  mkdir -p -- "$out"
  if ! sed -n '/^===JG-OUT-BEGIN===$/,/^===JG-OUT-END===$/{/^===JG-OUT-/d;p}' "$work/xfer.txt" |
    base64 -d | tar -xz -C "$out" --no-same-owner; then
    die "cannot unpack the out/ files sent back by the VM"
  fi
  note "$(awk -v a="$t0" -v q="$tq" -v b="$t1" -v k="$(du -k "$work/initramfs.gz" | cut -f1)" \
    'BEGIN{printf "VM run %.1f s: initramfs %.1f s (%.1f MiB), qemu boot+script+power-off %.1f s", b-a, q-a, k/1024, b-q}'); script exit status $status"
  exit "$status"
}

# ---------------------------------------------------------------------------------------
can_direct() {
  [[ ${JG_VM_FORCE:-0} != 1 ]] || return 1
  [[ $(id -u) -eq 0 ]] || return 1
  local ipb
  ipb=$(find_tool ip) || return 1
  "$ipb" link add dev jgvcanprobe type vcan >/dev/null 2>&1 || return 1
  "$ipb" link del dev jgvcanprobe >/dev/null 2>&1 || true
  return 0
}

run_direct() {
  local payload=$1 script=$2 out=$3 ipb rc=0
  need candump cansend timeout
  ipb=$(find_tool ip)
  note "this kernel has vcan: running $script directly (JG_VM_FORCE=1 uses the VM)"
  if ! "$ipb" link show dev vcan0 >/dev/null 2>&1; then
    "$ipb" link add dev vcan0 type vcan || die "cannot create vcan0"
    vcan_created=1
    "$ipb" link set vcan0 mtu 72 || die "cannot set the CAN FD MTU (72) on vcan0"
  fi
  "$ipb" link set up vcan0 || die "cannot bring up vcan0"
  [[ $(cat /sys/class/net/vcan0/mtu 2>/dev/null || echo 72) == 72 ]] ||
    note "warning: the existing vcan0 is not CAN FD capable (mtu $(cat /sys/class/net/vcan0/mtu))"
  mkdir -p "$work/payload"
  cp -RL --preserve=mode,timestamps -- "$payload/." "$work/payload/"
  rm -rf -- "$work/payload/out"
  mkdir -p "$work/payload/out"
  (cd "$work/payload" && exec timeout -k 10 "$timeout_s" /bin/sh "./$script" </dev/null 2>&1) &
  child_pid=$!
  wait "$child_pid" || rc=$?
  child_pid=""
  if ((rc == 124)); then
    echo "vm_run: ERROR: $script did not finish within ${timeout_s}s (JG_VM_TIMEOUT) and was killed" >&2
  fi
  mkdir -p -- "$out"
  cp -a -- "$work/payload/out/." "$out/"
  exit "$rc"
}

# ---------------------------------------------------------------------------------------
case ${1:-} in
  -h | --help)
    usage
    exit 0
    ;;
  --prepare)
    ensure_kernel
    echo "vm_run: kernel ready in $kernel_dir"
    exit 0
    ;;
esac
(($# == 2 || $# == 3)) || {
  usage >&2
  exit 2
}
payload=$1
script=$2
[[ -d $payload ]] || die "PAYLOAD_DIR '$payload' is not a directory"
payload=$(cd -- "$payload" && pwd)
[[ $script != /* ]] || die "SCRIPT must be relative to PAYLOAD_DIR, got '$script'"
[[ -f $payload/$script ]] || die "no script '$script' in $payload"
out=${3:-$payload/out}
mkdir -p -- "$out" || die "cannot create OUT_DIR '$out'"
out=$(cd -- "$out" && pwd)

work=$(mktemp -d "${TMPDIR:-/tmp}/jg-vm.XXXXXX")
# Both modes exit with the script's status.
if can_direct; then
  run_direct "$payload" "$script" "$out"
else
  run_vm "$payload" "$script" "$out"
fi
