# can.hil_socketcan, inside the VM (or directly on a host with vcan): the three joint drives
# as `jointguard node` processes and the simulated arm as `jointguard plant`, all on vcan0,
# with candump recording the traffic. hil_check.sh checks the results on the host.
set -eu
candump -r 4194304 -L vcan0 >out/capture.log &
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
candump -r 4194304 -L vcan0 >out/capture7.log &
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

# Faults mid-run (issue 14, docs/can.md "Faults"): the 3-joint run again, once with drive 2
# killed (SIGKILL) and restarted 0.3 s later, once with vcan0 down for 0.5 s, each after the
# master has sent 500 syncs; then with faults injected by spec from 0.5 s of plant time
# (cycle 500) for 0.2 s: drive 2's frames late (`node --fault late`), drive 2's controller
# bus-off (`node --fault bus-off:2`), a babbling node (`plant --fault babble`); then one run
# with the master's frame faults in four windows of 50 cycles: the sync and drive 2's
# samples duplicated from 0.3 s, drive 2's samples dropped from 0.5 s, corrupted from 0.8 s,
# NaN from 1.1 s (hil_check.sh runs the same specs in-process on the simulated bus). The
# master waits 100 ms for a drive that answered the previous cycle, 10 ms for one already
# silent (--timeout-ms 100). hil_check.sh checks the end states.
wait_syncs() {  # CAPTURE COUNT: until candump has logged COUNT cycle syncs (60 s at most)
  n=0
  while [ "$(grep -c ' 010##' "$1" 2>/dev/null || true)" -lt "$2" ]; do
    sleep 0.05
    n=$((n + 1))
    [ "$n" -lt 1200 ] || return 1
  done
}
node() {  # JOINT TAG [--fault SPEC]; $idle: exit after that long without a sync [s]
  j=$1 tag=$2
  shift 2
  exec ./jointguard node --joint "$j" --iface vcan0 --model ref3.yaml --friction friction.json --threshold threshold.json \
    --idle-exit "$idle" --startup-timeout 60 --json "out/${tag}_node$j.json" "$@" >"out/${tag}_node$j.txt" 2>&1
}
for fault in restart linkdown late busoff babble frames; do
  drive2="" plant_fault="" idle=3  # a loaded host may stall the VM for a second
  case $fault in
    late) drive2="--fault late@0.5:0.2" ;;
    busoff) drive2="--fault bus-off:2@0.5:0.2" ;;
    # No sync for the babble's 200 cycles, each closed after 10 ms (no drive answers): 2 s
    # and more of wall time, which the drives must not take for the end of the run.
    babble) plant_fault="--fault babble@0.5:0.2" idle=6 ;;
    frames)
      plant_fault="--fault duplicate:0x010@0.3:0.05 --fault duplicate:0x062@0.3:0.05 --fault drop:0x062@0.5:0.05"
      plant_fault="$plant_fault --fault corrupt:0x062@0.8:0.05 --fault nan-sensor:2@1.1:0.05"
      plant_fault="$plant_fault --trace out/trace_frames.csv --out out/rec_frames.csv"
      ;;
  esac
  dump=""
  if [ "$fault" = restart ] || [ "$fault" = linkdown ]; then
    candump -r 4194304 -L vcan0 >"out/capture_$fault.log" &
    dump=$!
    sleep 0.5
  fi
  node 1 "$fault" & p1=$!
  # shellcheck disable=SC2086 # the option and its spec: two words, or none
  node 2 "$fault" $drive2 & p2=$!
  node 3 "$fault" & p3=$!
  # shellcheck disable=SC2086
  ./jointguard plant hil_shoulder.yaml --iface vcan0 --friction friction.json --threshold threshold.json \
    --timeout-ms 100 --json "out/plant_$fault.json" $plant_fault >"out/plant_$fault.txt" 2>&1 &
  plant=$!
  if [ -n "$dump" ]; then
    wait_syncs "out/capture_$fault.log" 500 || { echo "hil_payload: $fault: no 500 syncs within 60 s"; rc=1; }
  fi
  if [ "$fault" = restart ]; then
    kill -9 "$p2"
    sleep 0.3
    node 2 restarted & p2=$!
  elif [ "$fault" = linkdown ]; then
    ip link set vcan0 down
    sleep 0.5
    ip link set vcan0 up
  fi
  wait "$plant" || rc=$?
  for p in $p1 $p2 $p3; do wait "$p" || rc=$?; done
  if [ -n "$dump" ]; then
    kill "$dump" 2>/dev/null || true
    wait "$dump" || true
  fi
  echo "== $fault"
  cat "out/plant_$fault.txt"
  [ "$fault" = restart ] || cat "out/${fault}_node2.txt"
done
exit "$rc"
