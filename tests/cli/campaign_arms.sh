#!/usr/bin/env bash
# Campaigns on six and seven joints (issue 31.4), small enough for CI: the Panda model
# (models/panda.yaml) and the UR10e (vendor URDF from ../shared/data/real/ur10e-static with
# models/ur10e_drive.yaml, its friction identified from motion_free as the plant's truth;
# skipped with a message when ../shared is absent). Each must simulate (the UR10e diverged
# at 6 ms before the plant stepped stiff friction implicitly), and its summary must hold:
#  - isolation counted where the true torques distinguish the link <= the ceiling (by
#    construction; a failure means the measure is broken);
#  - at least half of the collisions detected, and no false alarm in the collision-free run;
#  - float and Q16.16 (--compare-scalar q, the same measurements) detect every collision
#    either detects on the same cycle.
# Its cost is the simulated excitation's identification (the GA on 6 and 7 joints: 42 s of
# CPU for the Panda whatever --count and the run lengths, docs/results.md "Six and seven
# joints"), not the campaign: shrinking it further saves nothing.
# Usage: campaign_arms.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
PY=/usr/bin/python3
SMALL=(--scenario campaign --count 4 --calibration 30 --hold-calibration 30 --free-run 20 --compare-scalar q --jobs 2)
check() {  # check NAME JSON
  "$PY" - "$1" "$2" <<'PYEOF'
import json, sys
name, path = sys.argv[1], sys.argv[2]
s = json.load(open(path))["summary"]
runs = len(json.load(open(path))["runs"])
bad = []
if s["isolation_distinguished"] > s["isolation_ceiling"] + 1e-12:
    bad.append("isolation %.3f above its ceiling %.3f" % (s["isolation_distinguished"], s["isolation_ceiling"]))
if s["detection_rate"] < 0.5:
    bad.append("detected %.2f of %d" % (s["detection_rate"], runs))
c = s.get("same_cycle_other_scalar")
if c is None:
    bad.append("no float/Q16.16 comparison in the summary")
elif c["same_cycle"] != c["detected_by_either"]:
    bad.append("float and Q16.16 on the same cycle in %d of %d" % (c["same_cycle"], c["detected_by_either"]))
if s["false_alarms_per_hour"] > 0:
    bad.append("false alarms %.1f per hour" % s["false_alarms_per_hour"])
print("%s: %d runs, detected %.2f, isolation %.2f of ceiling %.2f, false alarms %.1f/h" %
      (name, runs, s["detection_rate"], s["isolation_distinguished"], s["isolation_ceiling"], s["false_alarms_per_hour"]))
for b in bad: print("FAIL: %s: %s" % (name, b))
sys.exit(1 if bad else 0)
PYEOF
}
fail=0
"$J" evaluate "${SMALL[@]}" --model "$SRC/models/panda.yaml" --json "$W/panda.json" > "$W/panda.txt" 2>&1 || { tail -3 "$W/panda.txt"; fail=1; }
[ -f "$W/panda.json" ] && { check panda "$W/panda.json" || fail=1; }
U="$SRC/../shared/data/real/ur10e-static"
if [ -f "$U/ur10e.urdf" ] && [ -f "$U/motion_free.csv" ]; then
  M=(--model "$U/ur10e.urdf" --drive "$SRC/models/ur10e_drive.yaml")
  "$J" identify "$U/motion_free.csv" --model "$U/ur10e.urdf" --drive "$U/drive.yaml" --json "$W/ur_fr.json" > /dev/null 2>&1
  "$J" evaluate "${SMALL[@]}" "${M[@]}" --plant-friction "$W/ur_fr.json" --json "$W/ur.json" > "$W/ur.txt" 2>&1 || { tail -3 "$W/ur.txt"; fail=1; }
  [ -f "$W/ur.json" ] && { check ur10e "$W/ur.json" || fail=1; }
  [ $fail -eq 0 ] || exit 1
else
  echo "UR10e skipped: ../shared/data/real/ur10e-static not found (the Panda ran)"
  [ $fail -eq 0 ] || exit 1
  exit 77
fi
