#!/usr/bin/env bash
# --fault on `simulate --bus sim` and `plant` (issue 14): malformed, out-of-range or
# non-injectable specs refused with exit 2 naming the spec, before anything runs or is
# written; a mid-run restart of drive 2 ends held, with the drive back (JSON).
# Usage: faults.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
S=scenarios/paper_collision_shoulder.yaml
H=tests/can/hil
expect2() {  # expect2 NEEDLE -- command...
  local needle="$1"
  shift 2
  set +e
  timeout 60 "$@" > "$W/out.txt" 2> "$W/err.txt"
  local rc=$?
  set -e
  if [ "$rc" != 2 ] || ! grep -qF -- "$needle" "$W/err.txt"; then
    echo "expected exit 2 with '$needle' from: $*; got $rc"
    cat "$W/err.txt"
    exit 1
  fi
}
sim=("$J" simulate "$S" --duration 2.2 --out "$W/never.csv" --bus sim --threshold "$H/threshold.json" --json "$W/never.json")
for bad in flood@0.5 drop drop@x drop@-1 drop@nan drop@0.5:0 drop:9@1 drop:0x800@1 restart@0.5 babble:2@1 link-down:1@1; do
  expect2 "'$bad'" -- "${sim[@]}" --fault "$bad"
done
expect2 "joint 4 does not exist" -- "${sim[@]}" --fault drop:4@0.5
expect2 "after the run's end" -- "${sim[@]}" --fault drop@3
expect2 "add --bus sim" -- "$J" simulate "$S" --out "$W/never.csv" --fault drop@0.5
expect2 "not injectable by the SocketCAN master" -- "$J" plant "$S" --iface vcan0 --threshold "$H/threshold.json" --fault restart:2@0.5
# late and bus-off on SocketCAN are the drive's own (`node --fault`); the drive refuses the others.
expect2 "jointguard node --joint J --fault late" -- "$J" plant "$S" --iface vcan0 --threshold "$H/threshold.json" --fault late:2@0.5
expect2 "jointguard node --joint J --fault bus-off" -- "$J" plant "$S" --iface vcan0 --threshold "$H/threshold.json" --fault bus-off:2@0.5
expect2 "a drive injects only late and bus-off" -- "$J" node --joint 2 --iface vcan0 --fault drop@0.5
expect2 "target none or 2" -- "$J" node --joint 2 --iface vcan0 --fault bus-off:3@0.5
expect2 "'late@x'" -- "$J" node --joint 2 --iface vcan0 --fault late@x
[ ! -e "$W/never.csv" ] && [ ! -e "$W/never.json" ] || { echo "a refused run wrote output"; exit 1; }
"$J" simulate "$S" --duration 2.2 --out "$W/r.csv" --bus sim --friction "$H/friction.json" --threshold "$H/threshold.json" \
  --fault restart:2@0.5:0.3 --json "$W/r.json" > "$W/out.txt"
/usr/bin/python3 - "$W/r.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
r, bus = j["runs"][0], j["bus"]
assert r["t_comm_fault"] is not None and 0.5 <= r["t_comm_fault"] <= 0.505, r
assert bus["restarts"] == 1 and not bus["communication_fault_at_end"], bus
assert all(d["ready"] and not d["communication_fault"] for d in j["drives_end"]), j["drives_end"]
assert j["faults"] == ["restart:2@0.5:0.3"], j["faults"]
PY
echo "faults.sh: bad specs refused with exit 2; restart:2@0.5:0.3 held and recovered"
