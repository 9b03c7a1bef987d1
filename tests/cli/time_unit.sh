#!/usr/bin/env bash
# Wrong units that every command read with exit 0 (issue 29):
# - time stamps in milliseconds: `identify t_ms.csv --model models/panda.yaml --rigid-body
#   --torque-kind joint` read "21000 rows at 1 Hz" and wrote link 4 at 8.75 kg. The reader
#   compares dq with the change of q over t and refuses, naming the file and the column t.
# - motor currents with a URDF and no --drive: read with K_I = 1 N·m/A. Refused, naming --drive.
# Usage: time_unit.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
expect() {  # expect RC NEEDLE -- command...
  local want="$1" needle="$2"
  shift 3
  set +e
  timeout 300 "$@" > "$W/out.txt" 2> "$W/err.txt"
  local rc=$?
  set -e
  if [ "$rc" != "$want" ] || ! grep -q -- "$needle" "$W/err.txt"; then
    echo "expected exit $want with '$needle' from: $*; got $rc"
    cat "$W/out.txt" "$W/err.txt"
    exit 1
  fi
}
MS=tests/data/time_unit/t_ms.csv
expect 1 "t_ms.csv:1: field 't': the velocities dq are 1000 times the change of q over t" -- \
  "$J" identify "$MS" --model models/panda.yaml --rigid-body --torque-kind joint --model-out "$W/never.yaml"
grep -q "milliseconds" "$W/err.txt" || { cat "$W/err.txt"; exit 1; }
[ ! -e "$W/never.yaml" ] || { echo "a model was written"; exit 1; }
printf 'plant_effects: []\n' > "$W/none.yaml"
expect 1 "field 't'" -- "$J" inject "$MS" --model models/panda.yaml --effects "$W/none.yaml" --out "$W/never.csv"
# The same motion in seconds is read.
awk -F, 'BEGIN { OFS = "," } NR == 1 { print; next } { $1 = $1 / 1000; print }' "$MS" > "$W/t_s.csv"
"$J" inject "$W/t_s.csv" --model models/panda.yaml --effects "$W/none.yaml" --out "$W/copy.csv" > /dev/null
# In microseconds: named as such.
awk -F, 'BEGIN { OFS = "," } NR == 1 { print; next } { $1 = $1 * 1000; print }' "$MS" > "$W/t_us.csv"
expect 1 "microseconds" -- "$J" inject "$W/t_us.csv" --model models/panda.yaml --effects "$W/none.yaml" --out "$W/never.csv"

# Currents (i<j>) with a URDF and no drive file: refused naming --drive; with it, read.
/usr/bin/python3 - "$W/two.csv" <<'PYEOF'
import math, sys
with open(sys.argv[1], "w") as f:
    f.write("t,q1,q2,dq1,dq2,i1,i2\n")
    for k in range(2000):
        t = k * 0.002
        f.write(f"{t:.3f},{0.3 * math.sin(t):.6f},{0.2 * math.sin(2 * t):.6f},{0.3 * math.cos(t):.6f},{0.4 * math.cos(2 * t):.6f},0.1000,-0.2000\n")
PYEOF
URDF=(--model tests/data/urdf/two_arms.urdf --tip left_hand)
expect 1 "give --drive FILE with k_i" -- "$J" identify "$W/two.csv" "${URDF[@]}" --rigid-body --model-out "$W/never.yaml"
expect 1 "give --drive FILE with k_i" -- "$J" identify "$W/two.csv" "${URDF[@]}" --json "$W/never.json"
printf 'joints: [left_shoulder, left_elbow]\nk_i: [2.0, 4.0]\n' > "$W/k.yaml"
set +e
"$J" identify "$W/two.csv" "${URDF[@]}" --drive "$W/k.yaml" --rigid-body --model-out "$W/id.yaml" > "$W/out.txt" 2> "$W/err.txt"
set -e
if grep -q -- "--drive" "$W/err.txt"; then echo "refused although --drive gives k_i"; cat "$W/err.txt"; exit 1; fi
echo "time_unit: ok"
