#!/usr/bin/env bash
# Findings a user can trust (issue 30): on the reference arm with a payload nobody declared,
#  - diagnose against the robot file alone (no --sim) names the payload at the arm level,
#    size within 20 %, with its uncertainty and its evidence against the recording's own
#    variation; the rigid-body refit that follows does not take the payload's place;
#  - --model-out writes the payload as a payload; the second round with that file claims no
#    new payload, writes it once, and every written file is read back by simulate and diagnose;
#  - a robot file rating the arm below the payload: not claimed, reported as unexplained;
#  - two runs of the same motion (sensor noise apart): nothing claimed; a recording shorter
#    than the tool can judge: nothing claimed, and it says so.
# Usage: named_causes.sh <jointguard> <source dir>
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
"$J" simulate scenarios/paper_excitation.yaml --model "$W/truth.yaml" --out "$W/real.csv" --seed 3 > /dev/null
"$J" diagnose --model models/ref3.yaml --real "$W/real.csv" --json "$W/d1.json" --model-out "$W/m2.yaml" > "$W/d1.txt"
"$J" diagnose --model "$W/m2.yaml" --real "$W/real.csv" --json "$W/d2.json" --model-out "$W/m3.yaml" > "$W/d2.txt"
"$J" simulate scenarios/paper_excitation.yaml --model "$W/m3.yaml" --out "$W/resim.csv" --seed 4 > /dev/null
"$PY" - "$W/d1.json" "$W/d2.json" "$W/m3.yaml" <<'PYEOF'
import json, sys, re
d1, d2 = (json.load(open(p)) for p in sys.argv[1:3])
pay = [f for f in d1["arm"]["findings"] if f["effect"] == "payload"]
assert pay, f"payload not named against the robot file: {[f['effect'] for f in d1['arm']['findings']]}"
p = pay[0]["params"]
assert 0.64 <= p["mass_kg"] <= 0.96, f"payload {p['mass_kg']} kg, truth 0.8"
assert p["mass_kg_sigma"] > 0 and pay[0]["evidence"]["z"] >= pay[0]["evidence"]["needed"], pay[0]
print(f"round 1: payload {p['mass_kg']:.3f} +/- {p['mass_kg_sigma']:.3f} kg (truth 0.8), null z {pay[0]['evidence']['z']:.1f}")
for f in d1["arm"]["findings"]:
    if f["effect"] == "rigid_body":  # what remains: the last link barely moves
        q = f["params"]
        change = abs(q["link3_mass_kg_after"] - q["link3_mass_kg_before"])
        assert change < 0.2 * 0.8, f"the rigid-body refit moved link 3 by {change:.3f} kg beside the payload"
again = [f for f in d2["arm"]["findings"] if f["effect"] == "payload"]
assert not again or abs(again[0]["params"]["mass_kg"]) < 0.16, f"round 2 claims a payload again: {again}"
m3 = open(sys.argv[3]).read()
assert len(re.findall(r"effect: payload", m3)) == 1, "the payload must be written once"
print("round 2: no new payload; m3.yaml holds it once")
PYEOF
"$J" diagnose --model "$W/m3.yaml" --real "$W/resim.csv" --no-rigid-body --json "$W/d3.json" > /dev/null
# identify --rigid-body from a robot file that carries the payload: fitted on top of it,
# written once (link 3 is 2.0 kg in the robot file; counted twice it would be 2.8).
"$J" identify "$W/real.csv" --model "$W/truth.yaml" --rigid-body --model-out "$W/id.yaml" > /dev/null
"$J" simulate scenarios/paper_excitation.yaml --model "$W/id.yaml" --out "$W/id_sim.csv" > /dev/null
"$PY" - "$W/id.yaml" <<'PYEOF'
import re, sys
text = open(sys.argv[1]).read()
assert len(re.findall(r"effect: payload", text)) == 1, "identify --rigid-body must write the payload once"
masses = [float(m) for m in re.findall(r"mass_kg: ([-0-9.e+]+)", text)]
assert abs(masses[2] - 2.0) < 0.4, f"link 3 written at {masses[2]} kg beside the payload (robot file 2.0 kg)"
print(f"identify --rigid-body on top of the payload: link 3 {masses[2]:.3f} kg, payload written once")
PYEOF
# The same for per-joint effects: a viscous change on joint 2 and an offset on joint 3 in the
# robot file and in the arm; identify fits the friction on top of them (without them in the
# file, the identified friction takes them: viscous +0.8, offset +0.5).
cp models/ref3.yaml "$W/joint_truth.yaml"
printf 'plant_effects:\n  - {effect: viscous, joint: 2, setting: {}, coefficients: [0.8]}\n  - {effect: current_offset, joint: 3, setting: {}, coefficients: [0.5]}\n' >> "$W/joint_truth.yaml"
"$J" simulate scenarios/paper_excitation.yaml --model "$W/joint_truth.yaml" --out "$W/joint_real.csv" --seed 3 > /dev/null
"$J" identify "$W/joint_real.csv" --model "$W/joint_truth.yaml" --rigid-body --json "$W/id_on_top.json" > /dev/null
"$J" identify "$W/joint_real.csv" --model models/ref3.yaml --rigid-body --json "$W/id_absent.json" > /dev/null
"$PY" - "$W/id_on_top.json" "$W/id_absent.json" <<'PYEOF'
import json, sys
top, absent = ([j["friction"] for j in json.load(open(f))["joints"]] for f in sys.argv[1:3])
dv, do = absent[1]["viscous"] - top[1]["viscous"], absent[2]["offset"] - top[2]["offset"]
print(f"identify on top of the file's per-joint effects: joint 2 viscous {top[1]['viscous']:.3f} (without them {absent[1]['viscous']:.3f}), joint 3 offset {top[2]['offset']:.3f} ({absent[2]['offset']:.3f})")
assert abs(dv - 0.8) < 0.1 and abs(do - 0.5) < 0.1, f"the file's effects were fitted again: viscous {dv:.3f}, offset {do:.3f} apart"
PYEOF

# Rated below the payload: reported as unexplained, not claimed.
sed 's/^name: \(.*\)$/name: \1\nrated_payload_kg: 0.5/' models/ref3.yaml > "$W/rated.yaml"
grep -q "^rated_payload_kg: 0.5" "$W/rated.yaml"
"$J" diagnose --model "$W/rated.yaml" --real "$W/real.csv" --json "$W/rated.json" > /dev/null
"$PY" - "$W/rated.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
assert not [f for f in d["arm"]["findings"] if f["effect"] == "payload"], "a payload above the rating was claimed"
u = [f for f in d["arm"]["unexplained"] if f["effect"] == "payload"]
assert u and 0.6 < u[0]["params"]["mass_kg"] < 1.0 and u[0]["params"]["bound_kg"] == 0.5, d["arm"]["unexplained"]
print(f"rated 0.5 kg: {u[0]['params']['mass_kg']:.3f} kg reported as unexplained, not claimed")
PYEOF

# Two runs of the same motion, sensor noise apart: nothing claimed.
"$J" simulate scenarios/paper_excitation.yaml --out "$W/a.csv" --seed 5 > /dev/null
"$J" simulate scenarios/paper_excitation.yaml --out "$W/b.csv" --seed 6 > /dev/null
"$J" diagnose --model models/ref3.yaml --real "$W/a.csv" --sim "$W/b.csv" --json "$W/same.json" > /dev/null
# Too short to judge: the first 1.5 s of the loaded run.
head -n 1501 "$W/real.csv" > "$W/short.csv"
"$J" diagnose --model models/ref3.yaml --real "$W/short.csv" --no-rigid-body --json "$W/short.json" > "$W/short.txt"
"$PY" - "$W/same.json" "$W/short.json" <<'PYEOF'
import json, sys
for path in sys.argv[1:3]:
    d = json.load(open(path))
    claims = [f["effect"] for f in d["arm"]["findings"]] + [f["effect"] for j in d["joints"] for f in j["findings"] if f["effect"] != "none"]
    assert not claims, f"{path}: claims {claims}"
short = json.load(open(sys.argv[2]))
assert any("too short to judge" in n for n in short["arm"]["notes"]), short["arm"]["notes"]
print("same motion twice: 0 claims; 1.5 s recording: 0 claims, said too short")
PYEOF
echo "named causes: ok"
