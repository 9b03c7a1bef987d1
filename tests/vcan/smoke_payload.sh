# vcan.smoke, inside the VM (or directly on a host with vcan): capture one classic CAN
# frame and one CAN FD frame (16 bytes, BRS) on vcan0 with candump; smoke_check.sh checks
# the capture on the host.
set -eu
candump -L vcan0 >out/capture.log &
dump=$!
sleep 1
cansend vcan0 123#DEADBEEF
cansend vcan0 321##1.00112233445566778899AABBCCDDEEFF
sleep 1
kill "$dump"
wait "$dump" || true
ip -details link show dev vcan0 >out/link.txt
echo "vcan.smoke: sent 2 frames"
