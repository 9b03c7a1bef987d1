#!/usr/bin/env bash
# smoke_check.sh OUT_DIR: the capture of vcan.smoke holds the classic and the FD frame.
set -euo pipefail
out=$1
echo "--- capture.log"
cat "$out/capture.log"
echo "---"
fail=0
grep -Eq ' vcan0 123#DEADBEEF$' "$out/capture.log" || { echo "FAIL: classic frame 123#DEADBEEF not captured"; fail=1; }
# candump prints the FD flags nibble; the kernel may add CANFD_FDF (0x4) to our BRS (0x1).
grep -Eq ' vcan0 321##[13579BDF]00112233445566778899AABBCCDDEEFF$' "$out/capture.log" ||
  { echo "FAIL: CAN FD frame 321##1.00112233445566778899AABBCCDDEEFF not captured"; fail=1; }
grep -q 'mtu 72' "$out/link.txt" || { echo "FAIL: vcan0 is not CAN FD capable (mtu 72)"; fail=1; }
((fail == 0)) && echo "vcan.smoke: both frames captured"
exit "$fail"
