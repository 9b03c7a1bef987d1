#!/usr/bin/env bash
# payload_run.sh WORK_DIR SCRIPT [FILE|DIR ...] [-- CHECK [ARG ...]]
#
# CTest helper behind jg_add_vcan_test(): makes WORK_DIR/payload afresh from SCRIPT and the
# FILEs/DIRs (each copied under its basename, symlinks followed), runs
#   vm_run.sh WORK_DIR/payload <basename of SCRIPT> WORK_DIR/out
# and, when the script succeeded and a CHECK is given, runs "bash CHECK WORK_DIR/out ARG..."
# on the host. The exit status is vm_run.sh's (77 = skipped) or the check's.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
(($# >= 2)) || { sed -n '2,9s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" >&2; exit 2; }
work=$1
script=$2
shift 2
files=()
while (($#)) && [[ $1 != -- ]]; do
  files+=("$1")
  shift
done
check=()
if (($#)); then
  shift
  check=("$@")
fi

rm -rf -- "$work/payload" "$work/out"
mkdir -p -- "$work/payload" "$work/out"
cp -L -- "$script" "$work/payload/"
for f in "${files[@]}"; do
  [[ -e $f ]] || { echo "payload_run: ERROR: $f does not exist" >&2; exit 125; }
  cp -RL --preserve=mode,timestamps -- "$f" "$work/payload/"
  # The VM only runs the executables: without their debug information a sanitizer build's
  # 200 MB binary shrinks to a few MB and fits the initramfs (it lives in the VM's RAM).
  copied="$work/payload/$(basename -- "$f")"
  if [[ -f $copied && -x $copied ]] && head -c 4 "$copied" | grep -q "ELF" && command -v objcopy >/dev/null; then
    objcopy --strip-debug "$copied" 2>/dev/null || true
  fi
done

rc=0
"$here/vm_run.sh" "$work/payload" "$(basename -- "$script")" "$work/out" || rc=$?
if ((rc != 0)); then
  exit "$rc"
fi
if ((${#check[@]})); then
  bash "${check[0]}" "$work/out" "${check[@]:1}"
fi
