#!/usr/bin/env bash
# The README's workflow examples, end to end, plus --help for every subcommand and the
# documented exit codes for bad input. Usage: run_workflow.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
for c in simulate identify calibrate evaluate replay diagnose inject bench demo node plant decode pipeline effects; do
  "$J" "$c" --help > /dev/null
done
"$J" simulate scenarios/paper_excitation.yaml --out "$W/excitation.csv"
"$J" simulate scenarios/free_motion.yaml --out "$W/free.csv" --duration 20
"$J" simulate scenarios/paper_collision_shoulder.yaml --out "$W/shoulder.csv"
"$J" identify "$W/excitation.csv" --model models/ref3.yaml --runs 2 --gain 150 --json "$W/friction.json"
"$J" calibrate "$W/free.csv" --model models/ref3.yaml --friction "$W/friction.json" --json "$W/threshold.json"
# Whole-arm rigid-body identification writes a robot file that --model accepts.
"$J" identify "$W/free.csv" --model models/ref3.yaml --rigid-body --model-out "$W/ref3_id.yaml" --json "$W/rbid.json" > /dev/null
grep -q '"base_parameters"' "$W/rbid.json" || { echo "rigid-body JSON lacks base_parameters"; exit 1; }
"$J" calibrate "$W/free.csv" --model "$W/ref3_id.yaml" --friction "$W/friction.json" --json "$W/threshold_id.json" > /dev/null
set +e
"$J" identify "$W/excitation.csv" --model models/panda.yaml --rigid-body --model-out "$W/never.yaml" 2> "$W/err.txt"; rc=$?
set -e
{ [ "$rc" = 1 ] && [ ! -e "$W/never.yaml" ]; } || { echo "rigid-body on a mismatched model: exit 1, nothing written (got $rc)"; exit 1; }
"$J" replay "$W/shoulder.csv" --model models/ref3.yaml --friction "$W/friction.json" --threshold "$W/threshold.json" --scalar q --json "$W/events.json"
grep -q '"link": 2' "$W/events.json" || { echo "replay did not isolate link 2"; exit 1; }
# The three steps in one command (tests/cli/pipeline.sh checks it against them by hand).
"$J" pipeline --model models/ref3.yaml --identify "$W/excitation.csv" --calibrate "$W/free.csv" "$W/shoulder.csv" --out "$W/arm" \
  --runs 2 > /dev/null
grep -q '"link": 2' "$W/arm/replay_shoulder.json" || { echo "pipeline: replay did not isolate link 2"; exit 1; }
"$J" evaluate --scenario paper --rate 125 --scalar q --free-run 20 --json "$W/paper.json"
grep -q '"detection_rate": 1.0' "$W/paper.json" || { echo "paper scenarios not all detected"; exit 1; }
"$J" diagnose --model models/ref3.yaml --real "$W/shoulder.csv" --sim "$W/shoulder.csv" --json "$W/diag.json" > "$W/diag.txt"
grep -q '"effect": "none"' "$W/diag.json" || { echo "a recording against itself must show nothing missing"; exit 1; }
# A known payload added to a recording's torque columns (tests/cli/inject.sh checks it).
"$J" inject "$W/free.csv" --model models/ref3.yaml --effects models/effects/ref3_payload.yaml --out "$W/free_payload.csv" > /dev/null
# The drives in the loop on the simulated CAN FD bus (in-process; the SocketCAN processes
# run in tests/can/hil).
"$J" simulate scenarios/paper_collision_shoulder.yaml --out "$W/shoulder_bus.csv" --bus sim --friction "$W/friction.json" \
  --threshold "$W/threshold.json" --json "$W/bus.json" > "$W/bus.txt"
grep -q '"link_isolated": 2' "$W/bus.json" || { echo "drives on the bus did not isolate link 2"; cat "$W/bus.txt"; exit 1; }
# The master's contact estimate from the drives' estimates: the shoulder collision's link
# (60 N at 0.25 m along link 2), its force within 50 % of the true force at the same cycle.
/usr/bin/python3 - "$W/bus.json" <<'PY' || { echo "the bus run's contact estimate"; cat "$W/bus.txt"; exit 1; }
import json, sys
c = json.load(open(sys.argv[1]))["runs"][0]["contact_estimate"]
assert c is not None and c["link"] == 2, c
assert abs(c["force"] - c["force_true_at_estimate"]) <= 0.5 * c["force_true_at_estimate"], c
assert abs(c["along_link"] - 0.25) <= 0.1, c
PY
set +e
"$J" node --joint 1 --iface jg-no-such-if0 --startup-timeout 1 2> "$W/err.txt"; rc=$?
set -e
[ "$rc" = 1 ] || { echo "expected exit 1 for a missing CAN interface, got $rc"; exit 1; }
grep -q "socketcan jg-no-such-if0" "$W/err.txt" || { echo "the error must name the interface"; cat "$W/err.txt"; exit 1; }
# Bad input: clear message, exit code 1 (work failed) or 2 (command line), nothing written.
printf 't,q1,dq1,i1\n0,0,nan,0\n' > "$W/bad.csv"
set +e
"$J" identify "$W/bad.csv" --model models/ref3.yaml --json "$W/never.json" 2> "$W/err.txt"; rc=$?
set -e
[ "$rc" = 1 ] || { echo "expected exit 1 for a malformed recording, got $rc"; exit 1; }
grep -q "bad.csv:2: field 'dq1'" "$W/err.txt" || { echo "error must name file, line and field"; cat "$W/err.txt"; exit 1; }
[ ! -e "$W/never.json" ] || { echo "nothing may be written on failure"; exit 1; }
set +e
"$J" evaluate --rate -5 > /dev/null 2>&1; rc=$?
set -e
[ "$rc" = 2 ] || { echo "expected exit 2 for a bad argument, got $rc"; exit 1; }
echo "workflow OK"
