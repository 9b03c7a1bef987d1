#!/usr/bin/env bash
# Several recordings of one arm (issue 30, item 4): `diagnose --real A --real B` on the
# reference arm carrying a 0.8 kg payload nobody declared, over two different motions (the
# paper's excitation and a random point-to-point motion):
#  - the payload is one parameter across both recordings: named once at the arm level, size
#    within 20 %, and, fitted on one recording, it improves the other (cross_motion_named);
#  - each recording predicted from the other (cross_motion): the joints' residual RMS never
#    worse; no effect claimed that made a left-out recording worse;
#  - a bad command line (two --real, one --sim) is refused with exit 2.
# Usage: cross_motion.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
PY=/usr/bin/python3
cp models/ref3.yaml "$W/truth.yaml"
cat >> "$W/truth.yaml" <<'YAML'
plant_effects:
  - {effect: payload, joint: 0, setting: {link: 3}, coefficients: [0.8, 0.16, 0, 0]}
YAML
"$J" simulate scenarios/paper_excitation.yaml --model "$W/truth.yaml" --out "$W/a.csv" --seed 3 > /dev/null
"$J" simulate scenarios/free_motion.yaml --model "$W/truth.yaml" --out "$W/b.csv" --seed 5 > /dev/null
"$J" diagnose --model models/ref3.yaml --real "$W/a.csv" --real "$W/b.csv" --json "$W/d.json" > "$W/d.txt"
grep -q "cross-motion: fitted on the others" "$W/d.txt"
"$PY" - "$W/d.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
pay = [f for f in d["arm"]["findings"] if f["effect"] == "payload"]
assert len(pay) == 1, f"one payload across both recordings, got {[f['effect'] for f in d['arm']['findings']]}"
m = pay[0]["params"]["mass_kg"]
assert 0.64 <= m <= 0.96, f"payload {m} kg, truth 0.8"
assert len(d["recordings"]) == 2, d.get("recordings")
named = d["cross_motion_named"]
fitted = [f for f in named if f["arm_causes"]]
assert fitted and all(f["arm_mse_ratio"] < 1.0 for f in fitted), f"the named payload does not transfer: {named}"
folds = d["cross_motion"]
assert len(folds) == 2, folds
for f in folds:
    for j in f["joints"]:
        assert j["rms_after"] <= j["rms_before"] * 1.001, f"{f['left_out']} joint {j['joint']} worse from the other recording: {j}"
claimed = {(j["joint"], f["effect"]) for j in d["joints"] for f in j["findings"]}
worse = {(j["joint"], e) for f in folds for j in f["joints"] for e in j["worse_effects"]}
assert not (claimed & worse), f"claimed although it made a left-out recording worse: {claimed & worse}"
print(f"payload {m:.3f} kg across 2 recordings (truth 0.8); transfers (MSE ratio {[round(f['arm_mse_ratio'], 3) for f in fitted]}); "
      f"withheld as not transferring: {sorted(worse)}")
PYEOF
set +e
"$J" diagnose --model models/ref3.yaml --real "$W/a.csv" --real "$W/b.csv" --sim "$W/a.csv" > /dev/null 2> "$W/err.txt"
rc=$?
set -e
[ "$rc" -eq 2 ] || { echo "two --real with one --sim: exit $rc, expected 2"; exit 1; }
grep -q "one per --real" "$W/err.txt"
echo "cross_motion: ok"
