#!/bin/busybox sh
# shellcheck shell=dash
# PID 1 of the vm_run.sh VM (busybox sh). vm_run.sh copies this file to /init in the
# initramfs and writes its settings to /etc/jg/:
#   modules         kernel modules to insmod, in dependency order (relative to /lib/modules/jg)
#   script          the test script, relative to /payload
#   script_timeout  seconds after which the script is killed (0 = no limit)
#   verbose         1: progress messages on the console
#   ip              path of iproute2's ip (this busybox runs its own applets first)
#   tools           paths of the real tools (ip, can-utils), linked into /usr/local/bin
# Serial ports: ttyS0 is the console (the script's stdout and stderr), ttyS1 carries the
# results back to the host: the files of /payload/out as a base64 gzip tar between
# ===JG-OUT-BEGIN=== and ===JG-OUT-END===, then ===JG-EXIT <status>===.
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
export HOME=/root TERM=dumb

# All busybox applets as symlinks (existing files such as /bin/sh are kept), then the real
# tools (ip, can-utils) in /usr/local/bin, first on PATH, and in place of applets of the
# same name (/sbin/ip).
/bin/busybox --install -s
while read -r t; do
  n=${t##*/}
  ln -sf "$t" "/usr/local/bin/$n"
  for d in /bin /sbin /usr/bin /usr/sbin; do
    if [ -L "$d/$n" ] && [ "$(readlink "$d/$n")" = /bin/busybox ]; then ln -sf "$t" "$d/$n"; fi
  done
done </etc/jg/tools

mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
exec </dev/null >/dev/console 2>&1
mkdir -p /dev/pts /dev/shm /run /root
mount -t devpts devpts /dev/pts
mount -t tmpfs -o mode=1777 tmpfs /dev/shm
# The initramfs is already RAM; a tmpfs on /tmp or /run would hide libraries that were
# copied there (a payload built under /tmp), so mount one only over an empty directory.
[ -n "$(ls -A /tmp)" ] || mount -t tmpfs -o mode=1777 tmpfs /tmp
[ -n "$(ls -A /run)" ] || mount -t tmpfs -o mode=0755 tmpfs /run
chmod 1777 /tmp

verbose=$(cat /etc/jg/verbose)
log() {
  if [ "$verbose" = 1 ]; then echo "vm_run(guest): $*"; fi
}
halt_vm() {
  sync
  poweroff -f
  # poweroff should not return; if it does, ask the kernel directly, and as a last
  # resort end PID 1: the kernel panics and panic=-1 + -no-reboot stop qemu.
  echo o >/proc/sysrq-trigger
  sleep 10
  exit 1
}
fail() {
  echo "vm_run(guest): ERROR: $*"
  echo "===JG-SETUP-FAILED===" >/dev/ttyS1
  halt_vm
}

ip=$(cat /etc/jg/ip)
"$ip" link set lo up || fail "cannot bring up lo"

while read -r m; do
  [ -n "$m" ] || continue
  log "insmod $m"
  insmod "/lib/modules/jg/$m" || fail "insmod $m failed"
done </etc/jg/modules

"$ip" link add dev vcan0 type vcan || fail "cannot create vcan0"
"$ip" link set vcan0 mtu 72 || fail "cannot set the CAN FD MTU (72) on vcan0"
"$ip" link set up vcan0 || fail "cannot bring up vcan0"
log "vcan0 up (CAN FD, mtu 72)"

script=$(cat /etc/jg/script)
limit=$(cat /etc/jg/script_timeout)
mkdir -p /payload/out
cd /payload || fail "no /payload"
log "running $script"
start=$(date +%s)
if [ "$limit" -gt 0 ]; then
  timeout -s TERM -k 5 "$limit" /bin/sh "./$script"
  rc=$?
  if [ "$rc" -eq 143 ] && [ $(($(date +%s) - start)) -ge "$limit" ]; then
    echo "vm_run(guest): ERROR: $script still running after ${limit}s (JG_VM_SCRIPT_TIMEOUT), killed"
  fi
else
  /bin/sh "./$script"
  rc=$?
fi
cd /
log "$script exited with status $rc after $(($(date +%s) - start))s"

mkdir -p /payload/out
{
  echo "===JG-OUT-BEGIN==="
  tar -c -C /payload/out . | gzip -c | base64
  echo "===JG-OUT-END==="
  echo "===JG-EXIT $rc==="
} >/dev/ttyS1
halt_vm
