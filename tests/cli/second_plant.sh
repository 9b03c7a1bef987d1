#!/usr/bin/env bash
# A second plant (issue 31 item 5), a small version of docs/results.md "A second plant":
# the arm of models/second3.yaml on the plant of models/second3_plant.yaml (its own masses,
# friction shape, sensors, PID controller and integrator), detection at its defaults.
#  - evaluate: the paper's three collisions at 1 kHz float and 125 Hz Q16.16 (all detected),
#    held pushes (no alarm in the quiet hold), 0 false alarms in each free run; shortened
#    calibrations (the figures in docs/results.md use the defaults, 3600 s + 1200 s). The
#    issue's delay (12 / 16 ms) and held-joint (2 N·m) targets are printed, not asserted:
#    the second plant does not reach them yet (docs/results.md "A second plant" says why;
#    second_plant.py --targets asserts them);
#  - the recording path at the defaults: identify and calibrate on 40 s of
#    scenarios/second3_calibration.yaml, replay of scenarios/second3_settle.yaml (moves that
#    stop and settle at rest for up to 4 s): no alarm; the paper's shoulder collision on the
#    second arm detected (first event within 30 ms; 20 ms measured, the target is 12 ms).
# Usage: second_plant.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
M="$SRC/models/second3.yaml"
P="$SRC/models/second3_plant.yaml"
E=("$J" evaluate --model "$M" --plant "$P" --calibration 300 --hold-calibration 300 --jobs 1)
"${E[@]}" --scenario paper --rate 1000 --free-run 120 --json "$W/paper1k.json" > "$W/paper1k.txt"
"${E[@]}" --scenario paper --rate 125 --scalar q --free-run 120 --json "$W/paper125.json" > "$W/paper125.txt"
"${E[@]}" --scenario held --rate 1000 --free-run 60 --json "$W/held.json" > "$W/held.txt"
/usr/bin/python3 "$SRC/tests/cli/second_plant.py" --check paper1k="$W/paper1k.json" paper125="$W/paper125.json" held="$W/held.json"

for s in calibration settle collision_shoulder; do
  sed -e "s#\.\./models#$SRC/models#" -e 's/^duration_s: 60/duration_s: 40/' "$SRC/scenarios/second3_$s.yaml" > "$W/$s.yaml"
done
"$J" simulate "$W/calibration.yaml" --out "$W/calib.csv" > /dev/null
"$J" simulate "$W/settle.yaml" --out "$W/settle.csv" > /dev/null
"$J" simulate "$W/collision_shoulder.yaml" --out "$W/shoulder.csv" > /dev/null
"$J" identify "$W/calib.csv" --model "$M" --runs 3 --json "$W/fr.json" > /dev/null
"$J" calibrate "$W/calib.csv" --model "$M" --friction "$W/fr.json" --json "$W/th.json" > /dev/null
R=("$J" replay --model "$M" --friction "$W/fr.json" --threshold "$W/th.json")
"${R[@]}" "$W/settle.csv" --json "$W/settle_events.json" > "$W/settle.txt"
"${R[@]}" "$W/shoulder.csv" --json "$W/shoulder_events.json" > /dev/null
/usr/bin/python3 - "$W" <<'PYEOF'
import json, sys
w = sys.argv[1]
s = json.load(open(f"{w}/settle_events.json"))
held, n = s["holding"]["held_samples"], 0
for line in open(f"{w}/settle.txt"):
    if line.startswith("holding (auto):"):
        n = int(line.split(" of ")[1].split()[0])
print(f"second plant, settling at rest (replay at the defaults): {held} of {n} samples held, alarms: {[e['t'] for e in s['events']]}")
shoulder = [e["t"] for e in json.load(open(f"{w}/shoulder_events.json"))["events"]]
print("second plant, paper shoulder collision (5.872 s) detected at", shoulder)
ok = True
if not (n > 0 and held > 0.3 * n):
    print("FAILED: the settling run must hold most of its dwells (else it tests nothing)"); ok = False
if s["events"]:
    print("FAILED: a joint settling at rest raised an alarm"); ok = False
if not (shoulder and 5.872 < shoulder[0] <= 5.872 + 0.030 + 1e-9):
    print("FAILED: the shoulder collision not detected within 30 ms"); ok = False
sys.exit(0 if ok else 1)
PYEOF
echo "second plant: ok"
