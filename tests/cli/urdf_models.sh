#!/usr/bin/env bash
# URDF models through the CLI as a user gives them: bad files end in exit 1 with the file
# named and nothing written (before: printf-format crashes, %n aborts, exit 0 with a mass of
# 0 or NaN rows); --tip, --drive; the vendor's UR10e when the real data folder is present.
# Usage: urdf_models.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
D="$SRC/tests/data/urdf"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
echo '{"joints": []}' > "$W/empty.json"
expect_refusal() {  # expect_refusal NEEDLE COMMAND...: exit 1, NEEDLE in stderr, no --json file
  local needle="$1"; shift
  set +e
  "$@" > "$W/out.txt" 2> "$W/err.txt"; local rc=$?
  set -e
  [ "$rc" = 1 ] || { echo "expected exit 1, got $rc: $*"; cat "$W/out.txt" "$W/err.txt"; exit 1; }
  grep -qF -- "$needle" "$W/err.txt" || { echo "the message must say '$needle': $*"; cat "$W/err.txt"; exit 1; }
  [ ! -e "$W/never.json" ] && [ ! -e "$W/never.csv" ] || { echo "something was written: $*"; exit 1; }
}
printf 't,q1,dq1,i1,q2,dq2,i2\n0,0,0,0,0,0,0\n0.001,0,0,0,0,0,0\n' > "$W/rec.csv"
for f in bad_mass_word bad_mass_nan bad_mass_unit bad_format_s bad_format_n bad_format_entity bad_inertia; do
  expect_refusal "$f.urdf" "$J" replay "$W/rec.csv" --model "$D/$f.urdf" --friction "$W/empty.json" --threshold "$W/empty.json" --json "$W/never.json"
  expect_refusal "$f.urdf" "$J" node --joint 1 --iface jg-no-such-if0 --model "$D/$f.urdf" --startup-timeout 1
done
expect_refusal "'j1' is prismatic" "$J" node --joint 1 --iface jg-no-such-if0 --model "$D/bad_prismatic.urdf" --startup-timeout 1
expect_refusal "left_hand, right_hand; choose one with --tip" "$J" node --joint 1 --iface jg-no-such-if0 --model "$D/two_arms.urdf"
expect_refusal "--tip: no link named 'hand'" "$J" node --joint 1 --iface jg-no-such-if0 --model "$D/two_arms.urdf" --tip hand
expect_refusal "the model's joint 'j6' is missing" "$J" node --joint 1 --iface jg-no-such-if0 --model "$D/skew_branch.urdf" \
  --drive "$D/drive_missing_joint.yaml"
# A link without <inertial> at the tip: the simulator refuses instead of writing NaN rows.
cp "$D/massless_tip.urdf" "$W/"
cat > "$W/massless.yaml" <<'YAML'
name: massless
model: massless_tip.urdf
duration_s: 1
trajectory: {type: random, start_rad: [0, 0.3], lower_rad: [-0.5, -0.5], upper_rad: [0.5, 0.5], max_speed_rad_s: 0.5, duration_s: 2}
YAML
expect_refusal "joint 'j2': the mass matrix is singular" "$J" simulate "$W/massless.yaml" --out "$W/never.csv"
# The same arm with an inertial simulates without a NaN.
sed 's|<link name="link2"></link>|<link name="link2"><inertial><origin xyz="0.1 0 0"/><mass value="1"/><inertia ixx="0.001" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>|' \
  "$D/massless_tip.urdf" > "$W/massless_tip.urdf"
"$J" simulate "$W/massless.yaml" --out "$W/ok.csv" > /dev/null
! grep -qi nan "$W/ok.csv" || { echo "NaN in the simulated recording"; exit 1; }
R="$SRC/../shared/data/real/ur10e-static"
if [ -f "$R/ur10e.urdf" ]; then
  joints() { for j in 1 2 3 4 5 6; do printf "$1" $j; [ $j -lt 6 ] && printf ', '; done; }
  printf '{"joints": [%s]}\n' "$(joints '{"joint": %d, "threshold": 50, "threshold_uncompensated": 50}')" > "$W/th.json"
  printf '{"joints": [%s]}\n' "$(joints '{"joint": %d, "sigma0": 1000, "sigma1": 10, "sigma2": 1, "tau_c": 1, "tau_s": 1.5, "w_s": 0.05}')" > "$W/fr.json"
  "$J" replay "$R/static_pushes.csv" --model "$R/ur10e.urdf" --drive "$R/drive.yaml" --friction "$W/fr.json" --threshold "$W/th.json" \
    --json "$W/ur.json" > /dev/null
  [ -s "$W/ur.json" ] || { echo "UR10e replay wrote nothing"; exit 1; }
else
  echo "real data folder absent: UR10e part skipped"
fi
echo "urdf models: ok"
