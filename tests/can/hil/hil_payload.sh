# can.hil_socketcan, inside the VM (or directly on a host with vcan): the three joint drives
# as `jointguard node` processes and the simulated arm as `jointguard plant`, all on vcan0,
# with candump recording the traffic. hil_check.sh checks the results on the host.
set -eu
candump -L vcan0 >out/capture.log &
dump=$!
sleep 0.5
pids=""
for j in 1 2 3; do
  ./jointguard node --joint "$j" --iface vcan0 --model ref3.yaml --friction friction.json --threshold threshold.json \
    --idle-exit 1 --startup-timeout 60 --json "out/node$j.json" >"out/node$j.txt" 2>&1 &
  pids="$pids $!"
done
rc=0
./jointguard plant hil_shoulder.yaml --iface vcan0 --friction friction.json --threshold threshold.json \
  --timeout-ms 20000 --json out/plant.json --trace out/trace.csv >out/plant.txt 2>&1 || rc=$?
for p in $pids; do wait "$p" || rc=$?; done
sleep 0.5
kill "$dump"
wait "$dump" || true
cat out/plant.txt out/node1.txt out/node2.txt out/node3.txt
[ "$rc" = 0 ] || exit "$rc"

# Seven drives (the Franka model, 400 Hz): the 7-joint traffic for the bus-load table.
candump -L vcan0 >out/capture7.log &
dump=$!
sleep 0.5
pids=""
for j in 1 2 3 4 5 6 7; do
  ./jointguard node --joint "$j" --iface vcan0 --model panda.yaml --rate 400 --threshold threshold7.json \
    --idle-exit 1 --startup-timeout 60 >"out/node7_$j.txt" 2>&1 &
  pids="$pids $!"
done
./jointguard plant panda_traffic.yaml --iface vcan0 --threshold threshold7.json --timeout-ms 20000 \
  --json out/plant7.json --trace out/trace7.csv >out/plant7.txt 2>&1 || rc=$?
for p in $pids; do wait "$p" || rc=$?; done
sleep 0.5
kill "$dump"
wait "$dump" || true
cat out/plant7.txt
exit "$rc"
