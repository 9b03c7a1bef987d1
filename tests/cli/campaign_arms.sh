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
# Friction is identified once per arm with `jointguard identify` (the Panda on a simulated
# excitation of all seven joints, the UR10e on the real motion_free, which is also its plant's
# truth) and given to evaluate with --friction: the identification (the GA on 6 and 7 joints,
# 42 s of CPU for the Panda) was most of the cost when evaluate ran it itself.
# A friction file evaluate cannot use (another arm's joint count; LuGre the firmware scalar
# does not hold at --rate) must stop it before any work with exit 1 and a message naming the
# file and the field.
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
refused() {  # refused NAME FIELD-TEXT ARGS...: evaluate must exit 1 naming the file and the field
  local name="$1" field="$2" rc=0
  shift 2
  "$J" evaluate "$@" > "$W/refused.txt" 2>&1 || rc=$?
  if [ "$rc" -ne 1 ] || ! grep -q "$W/$name" "$W/refused.txt" || ! grep -q -- "$field" "$W/refused.txt"; then
    echo "FAIL: evaluate with the friction file $name: exit $rc (1 expected, naming the file and '$field'):"; tail -3 "$W/refused.txt"
    return 1
  fi
}
fail=0
# The Panda's friction: identify on the shipped excitation of every joint about evaluate's home
# posture (scenarios/panda_excitation.yaml; its plant: the paper's Table 1, joint 3's beyond the
# third, as evaluate's).
"$J" simulate "$SRC/scenarios/panda_excitation.yaml" --out "$W/panda_excitation.csv" > /dev/null
"$J" identify "$W/panda_excitation.csv" --model "$SRC/models/panda.yaml" --json "$W/panda_fr.json" > /dev/null
# Refused files: the Panda's friction for the 3-joint reference arm (joint count), and a
# joint whose bristle stiffness Q16.16 does not hold at 1 kHz.
refused panda_fr.json "field 'joints': 7 entries, the model has 3 joints" --scenario paper --friction "$W/panda_fr.json" || fail=1
"$PY" - "$W/panda_fr.json" "$W/stiff_fr.json" <<'PYEOF'
import json, sys
f = json.load(open(sys.argv[1]))
f["joints"][3]["sigma0"] = 1e14
json.dump(f, open(sys.argv[2], "w"))
PYEOF
refused stiff_fr.json "joint 4: LuGre parameters" --scenario campaign --count 1 --model "$SRC/models/panda.yaml" --scalar q --friction "$W/stiff_fr.json" || fail=1
"$J" evaluate "${SMALL[@]}" --model "$SRC/models/panda.yaml" --friction "$W/panda_fr.json" --json "$W/panda.json" > "$W/panda.txt" 2>&1 || { tail -3 "$W/panda.txt"; fail=1; }
[ -f "$W/panda.json" ] && { grep -q "friction: $W/panda_fr.json" "$W/panda.txt" || { echo "FAIL: panda: the friction file's identity not printed"; fail=1; }; }
[ -f "$W/panda.json" ] && { "$PY" - "$W/panda.json" "$W/panda_fr.json" <<'PYEOF' || fail=1
import hashlib, json, sys
d = json.load(open(sys.argv[1]))
want = hashlib.sha256(open(sys.argv[2], "rb").read()).hexdigest()
got = d["identity"]["input_sha256"].get(sys.argv[2])
if got != want:
    print("FAIL: panda: identity.input_sha256 of the friction file %s, expected %s" % (got, want)); sys.exit(1)
PYEOF
}
[ -f "$W/panda.json" ] && { check panda "$W/panda.json" || fail=1; }
# The drives on the simulated bus (--compare-bus): seven drives' frames do not fit a 1 kHz
# cycle at 1 / 8 Mbit/s, which evaluate must say before any work (exit 2, naming the rate that
# fits); at 500 Hz every cycle completes and the drives detect what the host's estimator
# detects, at most a few cycles later (link i+k's terms reach joint i k cycles late).
rc=0
"$J" evaluate --scenario campaign --count 1 --model "$SRC/models/panda.yaml" --friction "$W/panda_fr.json" --compare-bus --json "$W/nobus.json" > "$W/nobus.txt" 2>&1 || rc=$?
if [ "$rc" -ne 2 ] || ! grep -q -- "--rate 637 or below" "$W/nobus.txt" || [ -f "$W/nobus.json" ]; then
  echo "FAIL: --compare-bus on seven joints at 1 kHz: exit $rc (2 expected, naming --rate 637)"; tail -3 "$W/nobus.txt"; fail=1
fi
"$J" evaluate --scenario campaign --count 3 --rate 500 --calibration 20 --hold-calibration 20 --free-run 5 --jobs 2 \
  --model "$SRC/models/panda.yaml" --friction "$W/panda_fr.json" --compare-bus --compare-scalar q --json "$W/bus.json" > "$W/bus.txt" 2>&1 || { tail -3 "$W/bus.txt"; fail=1; }
[ -f "$W/bus.json" ] && { "$PY" - "$W/bus.json" <<'PYEOF' || fail=1
import json, sys
d = json.load(open(sys.argv[1]))
s, bad = d["summary"], []
b, c = s.get("bus"), s.get("same_cycle_other_scalar")
if b is None or c is None or not c.get("on_bus"):
    bad.append("no bus figures in the summary")
else:
    if b["incomplete_cycles"] != 0: bad.append("%d incomplete cycles" % b["incomplete_cycles"])
    if not 0.5 < b["busy_s"] / b["elapsed_s"] < 1.0: bad.append("wire busy %.2f of the time" % (b["busy_s"] / b["elapsed_s"]))
    if c["both_detected"] != c["detected_by_either"]: bad.append("the bus and the host detect %d and %d" % (c["both_detected"], c["detected_by_either"]))
    if not 0.0 <= c["other_minus_first_s"]["min"] <= c["other_minus_first_s"]["max"] <= 6 * 0.002 + 1e-9:
        bad.append("the drives' detection %s s after the host's" % c["other_minus_first_s"])
    if any("bus" not in r for r in d["runs"]): bad.append("a run without its bus load")
print("bus: %s; %s" % (b, c))
for x in bad: print("FAIL: bus: %s" % x)
sys.exit(1 if bad else 0)
PYEOF
}
# The held-joint sweep pushes every link of the chain (7 here), each with its smallest push.
"$J" evaluate --scenario held --calibration 20 --hold-calibration 20 --free-run 2 --jobs 2 --model "$SRC/models/panda.yaml" \
  --friction "$W/panda_fr.json" --json "$W/held.json" > "$W/held.txt" 2>&1 || { tail -3 "$W/held.txt"; fail=1; }
[ -f "$W/held.json" ] && { "$PY" - "$W/held.json" <<'PYEOF' || fail=1
import json, sys
d = json.load(open(sys.argv[1]))
links = sorted({r["link_true"] for r in d["runs"] if r["held_push"] > 0})
smallest = d["summary"]["held_smallest_detected"]
print("held: links pushed %s, smallest detected %s" % (links, smallest))
if links != list(range(1, 8)) or len(smallest) != 7 or len(d["runs"]) != 36:
    print("FAIL: held: %d runs on links %s, %d smallest pushes (36, 1..7, 7 expected)" % (len(d["runs"]), links, len(smallest))); sys.exit(1)
PYEOF
}
U="$SRC/../shared/data/real/ur10e-static"
if [ -f "$U/ur10e.urdf" ] && [ -f "$U/motion_free.csv" ]; then
  M=(--model "$U/ur10e.urdf" --drive "$SRC/models/ur10e_drive.yaml")
  "$J" identify "$U/motion_free.csv" --model "$U/ur10e.urdf" --drive "$U/drive.yaml" --json "$W/ur_fr.json" > /dev/null 2>&1
  "$J" evaluate "${SMALL[@]}" "${M[@]}" --plant-friction "$W/ur_fr.json" --friction "$W/ur_fr.json" --json "$W/ur.json" > "$W/ur.txt" 2>&1 || { tail -3 "$W/ur.txt"; fail=1; }
  [ -f "$W/ur.json" ] && { check ur10e "$W/ur.json" || fail=1; }
  [ $fail -eq 0 ] || exit 1
else
  echo "UR10e skipped: ../shared/data/real/ur10e-static not found (the Panda ran)"
  [ $fail -eq 0 ] || exit 1
  exit 77
fi
