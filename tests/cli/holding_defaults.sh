#!/usr/bin/env bash
# Holding-aware detection at the defaults (issue 31.2), simulated reference arm at 1 kHz:
#  - calibrate on scenarios/calibration_motion.yaml (40 s, dwells up to 1 s) with no option:
#    the threshold file carries the holding detector's change thresholds;
#  - a motion that stops and settles at rest for up to 4 s after every move (60 s, half the
#    moves ending in an abrupt stop, another seed) replayed at the defaults: holding derived
#    from the recording for a large share of it, and no alarm;
#  - the paper's shoulder collision still detected within 50 ms;
#  - calibrate --holding always on that moving arm is refused naming the file, the joint and
#    the time; replay --holding still with a threshold file lacking the change thresholds is
#    refused naming the threshold file, not the recording.
# Usage: holding_defaults.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
M="$SRC/models/ref3.yaml"
sed -e "s#\.\./models#$SRC/models#" -e 's/^duration_s: 60/duration_s: 40/' "$SRC/scenarios/calibration_motion.yaml" > "$W/calib.yaml"
sed -e "s#\.\./models#$SRC/models#" -e 's/seed: 5/seed: 21/' -e 's/stop_share: 0.3/stop_share: 0.5/' \
  -e 's/dwell_max_s: 1.0/dwell_max_s: 4.0/' "$SRC/scenarios/calibration_motion.yaml" > "$W/settle.yaml"
"$J" simulate "$W/calib.yaml" --out "$W/calib.csv" > /dev/null
"$J" simulate "$W/settle.yaml" --out "$W/settle.csv" > /dev/null
"$J" simulate "$SRC/scenarios/paper_collision_shoulder.yaml" --out "$W/shoulder.csv" > /dev/null
"$J" identify "$W/calib.csv" --model "$M" --runs 3 --json "$W/fr.json" > /dev/null
"$J" calibrate "$W/calib.csv" --model "$M" --friction "$W/fr.json" --json "$W/th.json" > /dev/null
R=("$J" replay --model "$M" --friction "$W/fr.json" --threshold "$W/th.json")
"${R[@]}" "$W/settle.csv" --json "$W/settle_events.json" > "$W/settle.txt"
"${R[@]}" "$W/shoulder.csv" --json "$W/shoulder_events.json" > /dev/null
/usr/bin/python3 - "$W" <<'PYEOF'
import json, sys
w = sys.argv[1]
th = json.load(open(f"{w}/th.json"))
assert all(e["hold_change_threshold"] > 0 and e["hold_change_source"] in ("holds", "friction") for e in th["joints"]), th
s = json.load(open(f"{w}/settle_events.json"))
held, n = s["holding"]["held_samples"], 0
for line in open(f"{w}/settle.txt"):
    if line.startswith("holding (auto):"):
        n = int(line.split(" of ")[1].split()[0])
print("change thresholds:", [(round(e["hold_change_threshold"], 3), e["hold_change_source"]) for e in th["joints"]])
print(f"settling: {held} of {n} samples held, alarms: {[e['t'] for e in s['events']]}")
assert n > 0 and held > 0.3 * n, "the settling run must hold most of its dwells (else it tests nothing)"
assert not s["events"], "a joint settling at rest raised an alarm"
shoulder = [e["t"] for e in json.load(open(f"{w}/shoulder_events.json"))["events"]]
print("paper shoulder collision (5.872 s) detected at", shoulder)
assert len(shoulder) == 1 and 5.872 < shoulder[0] < 5.872 + 0.05, shoulder
PYEOF
# --holding always on a moving arm: refused (exit 1), naming the file, a joint and the time.
if "$J" calibrate "$W/settle.csv" --model "$M" --friction "$W/fr.json" --holding always > "$W/always.txt" 2>&1; then
  echo "FAILED: calibrate --holding always accepted a moving arm"; exit 1
fi
grep -q "settle.csv: --holding always, but the arm moves: joint [0-9]* is .* at t = " "$W/always.txt" || { cat "$W/always.txt"; exit 1; }
# A threshold file without the change thresholds: --holding still refused naming it.
/usr/bin/python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); [e.pop("hold_change_threshold") for e in d["joints"]]; json.dump(d, open(sys.argv[2], "w"))' "$W/th.json" "$W/th_old.json"
if "$J" replay "$W/shoulder.csv" --model "$M" --friction "$W/fr.json" --threshold "$W/th_old.json" --holding still > "$W/old.txt" 2>&1; then
  echo "FAILED: replay --holding still accepted a threshold file without change thresholds"; exit 1
fi
grep -q "th_old.json: --holding still needs the holding detector's change thresholds" "$W/old.txt" || { cat "$W/old.txt"; exit 1; }
# At the defaults the same file replays with the band alone and says so.
"${R[@]/$W\/th.json/$W/th_old.json}" "$W/shoulder.csv" | grep -q "note: .*th_old.json has no holding detector thresholds"
echo "holding defaults: ok"
