#!/usr/bin/env bash
# A robot file's plant_effects values range-checked when read (issue 29): a zero Stribeck
# velocity or time constant ended in "simulation diverged ... raise plant_rate_hz" naming no
# file; link 1.5 was applied to link 1; link 9 of a 3-link arm, a torque constant scale of
# -2 and a delay of 1e9 s were accepted with exit 0; a -5 kg payload got "the plant has no
# setting for it". Each is refused with exit 1 naming the file, the line and the field.
# Usage: plant_effect_ranges.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
n=0
# refused LINE FIELD NEEDLE: ref3 with LINE as its only plant effect must be refused.
refused() {
  n=$((n + 1))
  local model="$W/m$n.yaml"
  { cat models/ref3.yaml; echo "plant_effects:"; echo "  - $1"; } > "$model"
  local line
  line=$(wc -l < "$model")
  set +e
  timeout 60 "$J" simulate scenarios/free_motion.yaml --model "$model" --duration 0.02 --out "$W/never.csv" > "$W/out.txt" 2> "$W/err.txt"
  local rc=$?
  set -e
  if [ "$rc" != 1 ] || ! grep -q "m$n.yaml:$line:[0-9]*: field '[^']*$2'" "$W/err.txt" || ! grep -q -- "$3" "$W/err.txt"; then
    echo "expected exit 1 naming m$n.yaml:$line and field '$2' ('$3') for: $1; got $rc"
    cat "$W/err.txt"
    exit 1
  fi
  [ ! -e "$W/never.csv" ] || { echo "a recording was written for: $1"; exit 1; }
}
refused "{effect: stribeck, joint: 2, setting: {w_s: 0}, coefficients: [0.5], params: {}}" "w_s" "outside (0, 100\] rad/s"
refused "{effect: temperature_drift, joint: 1, setting: {time_constant_s: 0}, coefficients: [0.3], params: {}}" "time_constant_s" "outside"
refused "{effect: link_inertial_error, joint: 0, setting: {link: 1.5}, coefficients: [0.5, 0, 0, 0], params: {}}" "link" "link_inertial_error needs setting link in 1..3 (a whole number: a link of the arm), got 1.5"
refused "{effect: link_inertial_error, joint: 0, setting: {link: 9}, coefficients: [0.5, 0, 0, 0], params: {}}" "link" "needs setting link in 1..3 (a whole number: a link of the arm), got 9"
refused "{effect: torque_constant, joint: 1, coefficients: [-2], params: {}}" "coefficients" "would flip or erase"
refused "{effect: time_delay, joint: 1, coefficients: [-1e9], params: {}}" "coefficients" "\[-1, 1\] s as a delay"
refused "{effect: time_delay, joint: 1, coefficients: [-0.002], params: {delay_s: 1e9}}" "delay_s" "\[-1, 1\] s"
refused "{effect: payload, joint: 0, setting: {link: 3}, coefficients: [-5, 0, 0, 0], params: {mass_kg: -5}}" "coefficients" "a payload's mass"
refused "{effect: payload, joint: 0, setting: {link: 3}, coefficients: [5, 0, 0, 0], params: {mass_kg: 5e6}}" "mass_kg" "(0, 5000\] kg"
refused "{effect: backlash, joint: 2, coefficients: [], params: {gap_rad: -0.1}}" "gap_rad" "\[0, 0.5\] rad"
refused "{effect: joint_elasticity, joint: 2, coefficients: [], params: {stiffness_nm_per_rad: 0}}" "stiffness_nm_per_rad" "\[1, 1e9\]"
# inject reads the same list: the same check.
{ echo "plant_effects:"; echo "  - {effect: torque_constant, joint: 1, coefficients: [-2], params: {}}"; } > "$W/e.yaml"
"$J" simulate scenarios/free_motion.yaml --duration 0.05 --out "$W/free.csv" > /dev/null
set +e
"$J" inject "$W/free.csv" --model models/ref3.yaml --effects "$W/e.yaml" --out "$W/never2.csv" > /dev/null 2> "$W/err.txt"
rc=$?
set -e
[ "$rc" = 1 ] && grep -q "e.yaml:2:[0-9]*: field '[^']*coefficients'" "$W/err.txt" || { echo "inject: exit $rc"; cat "$W/err.txt"; exit 1; }
# Values in range still simulate (the shipped effects file, a payload of 0.5 kg).
{ cat models/ref3.yaml; sed -n '/^plant_effects:/,$p' models/effects/ref3_payload.yaml;
  echo "  - {effect: stribeck, joint: 2, setting: {w_s: 0.02}, coefficients: [0.2], params: {}}"
  echo "  - {effect: time_delay, joint: 1, coefficients: [-0.002], params: {delay_s: 0.002}}"; } > "$W/good.yaml"
"$J" simulate scenarios/free_motion.yaml --model "$W/good.yaml" --duration 0.05 --out "$W/good.csv" > "$W/out.txt"
grep -q "plant effect from the robot file: arm: payload 0.5 kg" "$W/out.txt" || { cat "$W/out.txt"; exit 1; }
if grep -q "not modelled" "$W/out.txt"; then cat "$W/out.txt"; exit 1; fi
echo "plant_effect_ranges: $n refused, in-range values simulated"
