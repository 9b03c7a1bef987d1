#!/usr/bin/env bash
# `jointguard inject` (docs/diagnosis.md, "Injection into real recordings"): known effects
# added to a recording's torque or current columns over its measured motion.
#  (b) `plant_effects: []` leaves the file byte-identical;
#  (c) a 0.5 kg payload on ref3's last link against (1) the same payload in the simulated
#      plant and (2) a point mass's inverse dynamics computed here from the D-H parameters;
#  (d) torque_constant / current_offset / coulomb on the current columns change them by the
#      expected amounts, every other field byte for byte;
#  (e) bad inputs: exit 1 or 2 naming the file (and line, field), nothing written.
# Usage: inject.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
PY=/usr/bin/python3

# (a) a short recording of the reference arm (8 s of the paper's excitation, 1 kHz).
"$J" simulate scenarios/paper_excitation.yaml --out "$W/ref.csv" --duration 8 > /dev/null

# (b) no effects: the same bytes.
printf 'plant_effects: []\n' > "$W/none.yaml"
"$J" inject "$W/ref.csv" --model models/ref3.yaml --effects "$W/none.yaml" --out "$W/none.csv" > /dev/null
cmp "$W/ref.csv" "$W/none.csv" || { echo "plant_effects: [] changed the recording"; exit 1; }
grep -q '"sha256": "'"$(sha256sum "$W/ref.csv" | cut -d' ' -f1)"'"' "$W/none.json" ||
  { echo "none.json does not name the source's SHA-256"; cat "$W/none.json"; exit 1; }

# (c) a payload: 0.5 kg at c = (0.15, 0.05, 0.03) m in the last link's frame.
cat > "$W/payload.yaml" <<'YAML'
plant_effects:
  - {effect: payload, joint: 0, setting: {link: 3}, coefficients: [0.5, 0.075, 0.025, 0.015], params: {mass_kg: 0.5}}
YAML
"$J" inject "$W/ref.csv" --model models/ref3.yaml --effects "$W/payload.yaml" --out "$W/payload.csv" > "$W/payload.txt"
grep -q "tau_m2: 8001 of 8001 rows changed" "$W/payload.txt" || { echo "payload: tau_m2 not changed on every row"; cat "$W/payload.txt"; exit 1; }
cp models/ref3.yaml "$W/truth.yaml"
printf 'plant_effects:\n' >> "$W/truth.yaml"
sed -n 's/^  - /  - /p' "$W/payload.yaml" >> "$W/truth.yaml"
"$J" simulate scenarios/paper_excitation.yaml --model "$W/truth.yaml" --out "$W/sim_payload.csv" --duration 8 > /dev/null
"$PY" - "$W/ref.csv" "$W/payload.csv" "$W/sim_payload.csv" models/ref3.yaml <<'PYEOF'
import csv, math, re, sys
ref_path, inj_path, sim_path, model = sys.argv[1:5]
def columns(path):
    with open(path) as f:
        r = csv.reader(f)
        head = next(r)
        rows = [x for x in r if x]
    return head, rows, {n: [float(row[i]) for row in rows] for i, n in enumerate(head)}
h0, rows0, a = columns(ref_path)
h1, rows1, b = columns(inj_path)
_, _, s = columns(sim_path)
assert h0 == h1 and len(rows0) == len(rows1), "header or row count changed"
for r0, r1 in zip(rows0, rows1):  # only the torque columns may differ, text for text
    for name, x, y in zip(h0, r0, r1):
        assert name.startswith("tau_m") or x == y, f"column {name} changed: {x} -> {y}"
n = len(a["t"])
rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
added = {j: [b[f"tau_m{j}"][k] - a[f"tau_m{j}"][k] for k in range(n)] for j in (1, 2, 3)}

# (1) The plant with the same payload, same seed: its torque minus the nominal run's.
# Smoothed over 0.1 s (the two runs' sensor quantisation differs), from t = 1 s on (at
# first the controller has not yet taken up the payload it does not know). What remains
# is the two runs' slightly different tracking (up to 2 mrad) through the controller
# and friction: 1-2 % of the payload torque on joints 2 and 3, 0.006 N·m on joint 1.
def smooth(v, w=101):
    c = [0.0]
    for x in v:
        c.append(c[-1] + x)
    return [(c[min(len(v), i + w // 2 + 1)] - c[max(0, i - w // 2)]) / (min(len(v), i + w // 2 + 1) - max(0, i - w // 2)) for i in range(len(v))]
late = [k for k in range(n) if a["t"][k] >= 1.0]
for j in (1, 2, 3):
    inj = smooth(added[j])
    sim = smooth([s[f"tau_m{j}"][k] - a[f"tau_m{j}"][k] for k in range(n)])
    d = rms([inj[k] - sim[k] for k in late])
    size = rms([inj[k] for k in late])
    print(f"joint {j}: payload torque RMS {size:.4f} N·m; injected - simulated (smoothed) RMS {d:.4f} N·m")
    assert d <= max(0.03 * size, 0.02), f"joint {j}: injected payload differs from the simulated one by {d:.4f} N·m RMS"

# (2) Independent: a point mass m at p needs tau_i = z_i . ((p - o_i) x m (a_p - g)),
# with the kinematics from the robot file's modified D-H parameters and a_p the second
# difference of p over +/-20 ms. The difference is the two acceleration estimates of the
# quantised encoders (the tool's Gaussian derivative of the motor-encoder velocity):
# 0.02 N·m, a sixth of the recording's current noise (0.01 A x 12 N·m/A).
m, c = 0.5, (0.15, 0.05, 0.03)
dh = []
for line in open(model):
    for key in ("a_prev_m", "alpha_prev_rad", "d_m"):
        found = re.match(r"\s*" + key + r":\s*([-0-9.eE+]+)", line)
        if found:
            if key == "a_prev_m":
                dh.append({})
            dh[-1][key] = float(found.group(1))
assert len(dh) == 3, dh
def mul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]
def kinematics(q):
    T = [[float(i == j) for j in range(4)] for i in range(4)]
    axes = []
    for l, th in zip(dh, q):  # RotX(alpha) TransX(a) RotZ(theta) TransZ(d)
        ca, sa, ct, st = math.cos(l["alpha_prev_rad"]), math.sin(l["alpha_prev_rad"]), math.cos(th), math.sin(th)
        T = mul(T, [[ct, -st, 0, l["a_prev_m"]], [st * ca, ct * ca, -sa, -sa * l["d_m"]], [st * sa, ct * sa, ca, ca * l["d_m"]], [0, 0, 0, 1]])
        axes.append(([T[i][3] for i in range(3)], [T[i][2] for i in range(3)]))
    return axes, [sum(T[i][k] * c[k] for k in range(3)) + T[i][3] for i in range(3)]
dt = a["t"][1] - a["t"][0]
h = int(round(0.02 / dt))
K = [kinematics([a[f"q{j}"][k] for j in (1, 2, 3)]) for k in range(n)]
err = {1: [], 2: [], 3: []}
ref = {1: [], 2: [], 3: []}
for k in range(h, n - h):
    axes, p = K[k]
    acc = [(K[k + h][1][i] - 2 * p[i] + K[k - h][1][i]) / (h * dt) ** 2 for i in range(3)]
    F = [m * acc[0], m * acc[1], m * (acc[2] + 9.81)]
    for j, (o, z) in enumerate(axes, start=1):
        r = [p[i] - o[i] for i in range(3)]
        tau = sum(zi * ci for zi, ci in zip(z, [r[1] * F[2] - r[2] * F[1], r[2] * F[0] - r[0] * F[2], r[0] * F[1] - r[1] * F[0]]))
        err[j].append(added[j][k] - tau)
        ref[j].append(tau)
for j in (1, 2, 3):
    print(f"joint {j}: point mass RMS {rms(ref[j]):.4f} N·m; injected - point mass RMS {rms(err[j]):.4f} N·m")
    assert rms(err[j]) <= max(0.02 * rms(ref[j]), 0.02), f"joint {j}: injected payload differs from the point mass's torque"
PYEOF

# (d) the current columns: torque_constant on joint 1, current_offset on 2, coulomb on 3.
cat > "$W/drive.yaml" <<'YAML'
plant_effects:
  - {effect: torque_constant, joint: 1, coefficients: [0.05]}
  - {effect: current_offset, joint: 2, coefficients: [0.3]}
  - {effect: coulomb, joint: 3, coefficients: [0.4]}
YAML
"$J" inject "$W/ref.csv" --model models/ref3.yaml --torque-kind current --effects "$W/drive.yaml" --out "$W/drive.csv" > /dev/null
"$PY" - "$W/ref.csv" "$W/drive.csv" <<'PYEOF'
import csv, sys
with open(sys.argv[1]) as f:
    rows0 = list(csv.reader(f))
with open(sys.argv[2]) as f:
    rows1 = list(csv.reader(f))
head = rows0[0]
assert rows1[0] == head and len(rows0) == len(rows1)
col = {n: i for i, n in enumerate(head)}
k_i = 12.0  # models/ref3.yaml: torque_constant_nm_per_a of every joint
dq3 = [float(r[col["dq3"]]) for r in rows0[1:]]
band = max(1e-4, 0.005 * max(abs(v) for v in dq3))  # the diagnosis's coulomb column: a sign with a linear band
def sign(w):
    return (1.0 if w > 0 else -1.0) if abs(w) >= band else w / band
for r0, r1 in zip(rows0[1:], rows1[1:]):
    for name, x, y in zip(head, r0, r1):
        if name not in ("i1", "i2", "i3"):
            assert x == y, f"{name} changed: {x} -> {y}"
    i1, i2, i3 = (float(r0[col[f"i{j}"]]) for j in (1, 2, 3))
    expect = {"i1": 1.05 * i1, "i2": i2 + 0.3 / k_i, "i3": i3 + 0.4 * sign(float(r0[col["dq3"]])) / k_i}
    for name, want in expect.items():
        got = float(r1[col[name]])
        assert abs(got - want) <= 1e-8 * max(1.0, abs(want)), f"{name} at t = {r0[0]}: {got} instead of {want}"
print("current columns: torque_constant x1.05, current_offset +0.025 A, coulomb +-0.0333 A as expected")
PYEOF

# Rows outside every uniform segment (a 2-row island between long gaps): left as they are.
"$PY" - "$W/gappy.csv" <<'PYEOF'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("t,q1,q2,q3,dq1,dq2,dq3,i1,i2,i3,extra\n")
    for t in [k * 0.001 for k in range(1000)] + [2.0, 2.001] + [3.0 + k * 0.001 for k in range(800)]:
        w = math.pi
        f.write(f"{t:.4f},{0.3 * math.sin(w * t):.6f},{0.6 + 0.3 * math.sin(w * t):.6f},-0.8,{0.3 * w * math.cos(w * t):.6f},"
                f"{0.3 * w * math.cos(w * t):.6f},0,0.1,1.0,0.2,7\n")
PYEOF
"$J" inject "$W/gappy.csv" --model models/ref3.yaml --effects "$W/payload.yaml" --out "$W/gappy_out.csv" > "$W/gappy.txt"
grep -q "2 rows outside every uniform segment" "$W/gappy.txt" || { echo "rows outside the segments not reported"; cat "$W/gappy.txt"; exit 1; }
diff <(sed -n '1002,1003p' "$W/gappy.csv") <(sed -n '1002,1003p' "$W/gappy_out.csv") > /dev/null || { echo "the island's rows changed"; exit 1; }
! diff <(sed -n '1004p' "$W/gappy.csv") <(sed -n '1004p' "$W/gappy_out.csv") > /dev/null || { echo "the segment after the gap unchanged"; exit 1; }

# (e) bad inputs: exit code, the message naming the file (line, field), no output.
expect() {  # expect RC TEXT ARGS...: the command exits RC, stderr contains TEXT, out.csv not written
  local rc=$1 text=$2
  shift 2
  set +e
  "$J" inject "$@" > "$W/stdout.txt" 2> "$W/err.txt"
  local got=$?
  set -e
  if [ "$got" != "$rc" ] || ! grep -qF -- "$text" "$W/err.txt" || [ -e "$W/bad.csv" ] || [ -e "$W/bad.json" ]; then
    echo "inject $*: expected exit $rc with '$text', got $got:"
    cat "$W/err.txt"
    exit 1
  fi
}
bad() {  # bad NAME ENTRY: an effects file with one entry
  printf 'plant_effects:\n  - %s\n' "$2" > "$W/$1.yaml"
}
R=("$W/ref.csv" --model models/ref3.yaml --out "$W/bad.csv")
bad unknown '{effect: payloads, joint: 0, coefficients: [0.5, 0, 0, 0]}'
expect 1 "unknown.yaml:2:14: field 'plant_effects[0].effect': 'payloads' is not an effect" "${R[@]}" --effects "$W/unknown.yaml"
bad backlash '{effect: backlash, joint: 2, params: {gap_rad: 0.001}}'
expect 1 "backlash.yaml:2:14: field 'plant_effects[0].effect': 'backlash' changes the gear's deflection" "${R[@]}" --effects "$W/backlash.yaml"
bad joint '{effect: viscous, joint: 4, coefficients: [0.1]}'
expect 1 "joint.yaml:2:30: field 'plant_effects[0].joint': expected 0 (the arm) or a joint 1..3" "${R[@]}" --effects "$W/joint.yaml"
bad nan '{effect: viscous, joint: 1, coefficients: [.nan]}'
expect 1 "nan.yaml:2:48: field 'plant_effects[0].coefficients[0]'" "${R[@]}" --effects "$W/nan.yaml"
bad typo '{effect: payload, joint: 0, setting: {picked_up_at: 1}, coefficients: [0.5, 0, 0, 0]}'
expect 1 "field 'plant_effects[0].setting.picked_up_at': 'payload' has no setting 'picked_up_at'" "${R[@]}" --effects "$W/typo.yaml"
bad count '{effect: viscous, joint: 1, coefficients: [0.1, 0.2]}'
expect 1 "field 'plant_effects[0].coefficients': 'viscous' takes 1 coefficient(s), got 2" "${R[@]}" --effects "$W/count.yaml"
bad link '{effect: link_inertial_error, joint: 0, setting: {link: 9}, coefficients: [0.1, 0, 0, 0]}'
expect 1 "field 'plant_effects[0].setting.link': link_inertial_error needs setting link in 1..3" "${R[@]}" --effects "$W/link.yaml"
bad curve '{effect: coulomb, joint: 2, setting: {model_curve: 1}, coefficients: [0.6]}'
expect 1 "give that friction with --friction" "${R[@]}" --effects "$W/curve.yaml"
printf 'plant_effect: []\n' > "$W/nolist.yaml"
expect 1 "nolist.yaml" "${R[@]}" --effects "$W/nolist.yaml"
# A joint torque sensor's reading has no current channel.
bad sensor '{effect: torque_constant, joint: 1, coefficients: [0.05]}'
expect 1 "field 'plant_effects[0].effect': 'torque_constant' is an error of the motor current's channel" "${R[@]}" \
  --torque-kind joint --effects "$W/sensor.yaml"
# Outputs that would overwrite an input, and bad command lines: exit 2.
cp "$W/ref.csv" "$W/keep.csv"
expect 2 "would overwrite the recording" "$W/ref.csv" --model models/ref3.yaml --effects "$W/payload.yaml" --out "$W/ref.csv"
cmp "$W/ref.csv" "$W/keep.csv" || { echo "the input was changed"; exit 1; }
expect 2 "would overwrite the recording's side file" "$W/ref.csv" --model models/ref3.yaml --effects "$W/payload.yaml" --out "$W/ref.txt"
[ ! -e "$W/ref.txt" ] || { echo "ref.txt written"; exit 1; }
expect 2 "is a folder" "$W/ref.csv" --model models/ref3.yaml --effects "$W/payload.yaml" --out "$W"
expect 2 "--effects is required" "$W/ref.csv" --model models/ref3.yaml --out "$W/bad.csv"
expect 2 "no-such.yaml" "${R[@]}" --effects "$W/no-such.yaml"
# Currents with a URDF: no torque constant without a drive file's k_i.
"$PY" - "$W/two.csv" <<'PYEOF'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("t,q1,q2,dq1,dq2,i1,i2\n")
    for k in range(500):
        t = k * 0.002
        f.write(f"{t:.3f},{0.3 * math.sin(t):.6f},{0.2 * math.sin(2 * t):.6f},{0.3 * math.cos(t):.6f},{0.4 * math.cos(2 * t):.6f},0.1000,-0.2000\n")
PYEOF
bad viscous '{effect: viscous, joint: 2, coefficients: [0.5]}'
expect 1 "give --drive FILE with k_i" "$W/two.csv" --model tests/data/urdf/two_arms.urdf --tip left_hand --effects "$W/viscous.yaml" --out "$W/bad.csv"
printf 'joints: [left_shoulder, left_elbow]\nk_i: [2.0, 4.0]\n' > "$W/k.yaml"
"$J" inject "$W/two.csv" --model tests/data/urdf/two_arms.urdf --tip left_hand --drive "$W/k.yaml" --effects "$W/viscous.yaml" \
  --out "$W/two_out.csv" > /dev/null
"$PY" - "$W/two.csv" "$W/two_out.csv" <<'PYEOF'
import csv, sys
a = list(csv.reader(open(sys.argv[1])))
b = list(csv.reader(open(sys.argv[2])))
for r0, r1 in zip(a[1:], b[1:]):
    assert r0[:6] == r1[:6]
    want = float(r0[6]) + 0.5 * float(r0[4]) / 4.0  # viscous 0.5 N·m s/rad x dq2, over K_I = 4 N·m/A
    assert abs(float(r1[6]) - want) < 1e-8, (r0, r1)
print("URDF with --drive k_i: viscous on i2 as expected")
PYEOF
echo "inject: ok"
