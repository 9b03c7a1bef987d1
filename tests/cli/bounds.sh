#!/usr/bin/env bash
# Bad input that used to hang or crash (issue 14): a 40 kB DBC line (std::regex recursion),
# plant_rate_hz 1e9 and duration_s 1e12 in a scenario, --duration 1e12, --plant-rate out of range
# or under the control rate, a diverging stiff gear. Each must exit 1
# (file, line and field named) or 2 (bad command line), quickly, writing nothing. Also duplicate
# YAML keys and the friction/threshold JSON messages.
# Usage: bounds.sh <jointguard> <source dir>
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
  timeout 60 "$@" > "$W/out.txt" 2> "$W/err.txt"
  local rc=$?
  set -e
  if [ "$rc" != "$want" ] || ! grep -q -- "$needle" "$W/err.txt"; then
    echo "expected exit $want with '$needle' from: $*; got $rc"
    cat "$W/err.txt"
    exit 1
  fi
}
# variant SED_EXPR SCENARIO OUT: a shipped scenario edited by SED_EXPR, written to $W/OUT with
# its model path made absolute (the copy is read from $W).
variant() {
  sed "$1" "scenarios/$2" | sed "s#model: ../models/ref3.yaml#model: $SRC/models/ref3.yaml#" > "$W/$3"
}
{ echo 'VERSION ""'; echo 'BO_ 16 sync: 8 master'; printf ' SG_ x : 0|8@1+ (1,0) [0|1] "'; head -c 40000 /dev/zero | tr '\0' 'a'; echo '" node'; } > "$W/long.dbc"
echo "(0.000000) vcan0 010#00" > "$W/capture.log"
expect 1 "long.dbc:3" -- "$J" decode "$W/capture.log" --dbc "$W/long.dbc"
variant 's/^control_rate_hz: 1000$/control_rate_hz: 1000\nplant_rate_hz: 1e9/' paper_excitation.yaml fast.yaml
expect 1 "plant_rate_hz" -- "$J" simulate "$W/fast.yaml" --out "$W/never.csv"
variant 's/^control_rate_hz: 1000$/control_rate_hz: 1000\nduration_s: 1e12/' paper_excitation.yaml long.yaml
expect 1 "duration_s" -- "$J" simulate "$W/long.yaml" --out "$W/never.csv"
expect 2 "duration" -- "$J" simulate scenarios/paper_excitation.yaml --duration 1e12 --out "$W/never.csv"
expect 2 "plant-rate" -- "$J" simulate scenarios/paper_excitation.yaml --plant-rate 1e9 --out "$W/never.csv"
expect 1 "paper_excitation.yaml's control_rate_hz" -- "$J" simulate scenarios/paper_excitation.yaml --plant-rate 500 --out "$W/never.csv"
[ ! -e "$W/never.csv" ] || { echo "a refused --plant-rate wrote $W/never.csv"; exit 1; }
# A generated motion of 76 days (found by the scenario fuzzer: its moves filled the memory).
variant 's/^  duration_s: .*/  duration_s: 6566666/' free_motion.yaml random_long.yaml
expect 1 "random_long.yaml:.*duration_s.*7 days" -- "$J" simulate "$W/random_long.yaml" --out "$W/never.csv"
# A pick task of 63 million repetitions (the scenario fuzzer's finding in the sixth session:
# 2.7 GB of waypoints, out of memory): refused naming file, line and field, like a generated
# motion beyond 7 days.
variant 's/^  repetitions: .*/  repetitions: 63000000/' paper_collision_shoulder.yaml pick_long.yaml
expect 1 "pick_long.yaml:[0-9]*:[0-9]*: .*repetitions.*expected 1..81729 (7 days)" -- "$J" simulate "$W/pick_long.yaml" --out "$W/never.csv"
# A calibration motion's levels beyond int (once cast before their check, so they could wrap
# into range) and speed_steps out of range: refused at the field's own line.
variant 's/^  levels: .*/  levels: 4294967298/' calibration_motion.yaml levels.yaml
expect 1 "levels.yaml:18:[0-9]*: field 'trajectory.levels': expected 2..100" -- "$J" simulate "$W/levels.yaml" --out "$W/never.csv"
variant 's/^  speed_steps: .*/  speed_steps: 11/' calibration_motion.yaml steps.yaml
expect 1 "steps.yaml:19:[0-9]*: field 'trajectory.speed_steps': expected 1..10" -- "$J" simulate "$W/steps.yaml" --out "$W/never.csv"
# Gears of 3e6 N·m/rad at the default plant rate diverge: exit 1, no NaN recording.
variant 's/^control_rate_hz: 1000$/control_rate_hz: 1000\nelasticity: {stiffness_nm_per_rad: [3e6, 3e6, 3e6]}/' paper_excitation.yaml stiff.yaml
expect 1 "diverged" -- "$J" simulate "$W/stiff.yaml" --out "$W/never.csv"
[ ! -e "$W/never.csv" ] || { echo "a refused run wrote its recording"; exit 1; }
# A drive file's rotor inertia of 5e37 kg m^2 (the drive fuzzer's finding): refused naming the
# drive file, line and field, not reported as a singular mass matrix of the robot file. And
# `simulate --drive` acts on the plant (it was accepted and ignored without --bus): the
# motor currents follow the drive file's K_I.
expect 1 "huge_rotor_inertia.yaml:4:22: field 'rotor_inertia_kg_m2': joint 'elbow'" -- "$J" simulate \
  scenarios/paper_collision_shoulder.yaml --drive tests/fuzz/regressions/drive/huge_rotor_inertia.yaml --out "$W/never.csv"
[ ! -e "$W/never.csv" ] || { echo "a refused drive file let simulate write its recording"; exit 1; }
printf 'joints: [waist, shoulder, elbow]\nk_i: [5.0, 10.0, 10.0]\n' > "$W/k5.yaml"
printf 'joints: [waist, shoulder, elbow]\nk_i: [2.5, 10.0, 10.0]\n' > "$W/k2.yaml"
for k in k5 k2; do
  "$J" simulate scenarios/paper_collision_shoulder.yaml --drive "$W/$k.yaml" --duration 0.2 --out "$W/$k.csv" > /dev/null
done
/usr/bin/python3 - "$W/k5.csv" "$W/k2.csv" <<'PY' || { echo "simulate --drive: the waist's current must double with half its K_I"; exit 1; }
import csv, sys
a, b = (list(csv.DictReader(open(f))) for f in sys.argv[1:3])
# Summed over the run (the current sensor's noise, 0.01 A rms, does not scale with K_I).
ratio = sum(abs(float(r["i1"])) for r in b) / sum(abs(float(r["i1"])) for r in a)
same = sum(abs(float(r["i2"])) for r in b) / sum(abs(float(r["i2"])) for r in a)
assert 1.9 <= ratio <= 2.1 and 0.97 <= same <= 1.03, (ratio, same)
PY
# An extended identifier is not the 11-bit cycle sync; binary input is not echoed raw.
printf '(0.000000) vcan0 00000010#00\n' > "$W/ext.log"
set +e
"$J" decode "$W/ext.log" > "$W/ext.txt" 2>&1
set -e
grep -q "0 cycles" "$W/ext.txt" && grep -q "is extended" "$W/ext.txt" || { echo "extended 0x10 counted as a sync"; cat "$W/ext.txt"; exit 1; }
printf '(0.000000) vcan0 \x01\x02\xff#00\n' > "$W/bin.log"
expect 1 "'???' is not hexadecimal" -- "$J" decode "$W/bin.log"
# --margin nan or negative: a bad command line (exit 2), no thresholds written.
expect 2 "margin" -- "$J" calibrate tests/data/recordings/held_arm.csv --model models/ref3.yaml \
  --friction tests/data/recordings/ref3_friction.json --margin nan --json "$W/never.json"
expect 2 "margin" -- "$J" calibrate tests/data/recordings/held_arm.csv --model models/ref3.yaml \
  --friction tests/data/recordings/ref3_friction.json --margin -100 --json "$W/never.json"
# --time-window with nan (once read as 0..3) or FROM after TO: a bad command line.
expect 2 "time-window" -- "$J" calibrate tests/data/recordings/held_arm.csv --model models/ref3.yaml \
  --friction tests/data/recordings/ref3_friction.json --time-window nan 3 --json "$W/never.json"
expect 2 "FROM must be before TO" -- "$J" calibrate tests/data/recordings/held_arm.csv --model models/ref3.yaml \
  --friction tests/data/recordings/ref3_friction.json --time-window 3 1 --json "$W/never.json"
# --shard without --json: a bad command line (exit 2), not a failed run.
expect 2 "needs --json" -- "$J" evaluate --scenario campaign --count 2 --shard 1/2
[ ! -e "$W/never.json" ] || { echo "a refused calibration wrote its thresholds"; exit 1; }
# Duplicate YAML keys (yaml-cpp keeps both and reads the first): refused naming file, line
# and key, in robot files and in scenarios.
sed 's/^    alpha_prev_rad: 0.0$/    alpha_prev_rad: 0.0\n    a_prev_m: 0.5/' models/ref3.yaml > "$W/dup_robot.yaml"
expect 1 "dup_robot.yaml:13:5: field 'joints\[0\].a_prev_m': duplicate key (first given on line 11)" -- \
  "$J" replay tests/data/recordings/held_arm.csv --model "$W/dup_robot.yaml" \
  --friction tests/data/recordings/ref3_friction.json --threshold tests/data/recordings/ref3_threshold.json
# An alias inside its own anchor nests without end (found by the robot_yaml fuzzer: a stack
# overflow in the key check): refused naming the file, line and column.
{ cat models/ref3.yaml; echo 'loop: &loop [*loop, 1]'; } > "$W/cyclic_robot.yaml"
expect 1 "cyclic_robot.yaml:[0-9]*:[0-9]*: nested deeper than 64 levels" -- \
  "$J" replay tests/data/recordings/held_arm.csv --model "$W/cyclic_robot.yaml" \
  --friction tests/data/recordings/ref3_friction.json --threshold tests/data/recordings/ref3_threshold.json
# Aliases that expand (a "billion laughs" document) are refused after 10,000 nodes, naming
# the file; a document of about 9,000 nodes is checked through to its unknown key, one with a
# list of 10,000 is refused by the count.
{ cat models/ref3.yaml; echo 'notes: ['; seq -s , 1 8990; echo ']'; } > "$W/long_list_robot.yaml"
expect 1 "long_list_robot.yaml:[0-9]*:[0-9]*: field 'notes': unknown key" -- \
  "$J" replay tests/data/recordings/held_arm.csv --model "$W/long_list_robot.yaml" \
  --friction tests/data/recordings/ref3_friction.json --threshold tests/data/recordings/ref3_threshold.json
{ cat models/ref3.yaml; echo 'notes: ['; seq -s , 1 10000; echo ']'; } > "$W/longer_list_robot.yaml"
expect 1 "longer_list_robot.yaml:[0-9]*:[0-9]*: more than 10000 YAML nodes" -- \
  "$J" replay tests/data/recordings/held_arm.csv --model "$W/longer_list_robot.yaml" \
  --friction tests/data/recordings/ref3_friction.json --threshold tests/data/recordings/ref3_threshold.json
{ cat models/ref3.yaml; echo 'a: &a [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]'; echo 'b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]';
  echo 'c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]'; echo 'd: [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]'; } > "$W/laughs_robot.yaml"
expect 1 "laughs_robot.yaml:[0-9]*:[0-9]*: more than 10000 YAML nodes" -- \
  "$J" replay tests/data/recordings/held_arm.csv --model "$W/laughs_robot.yaml" \
  --friction tests/data/recordings/ref3_friction.json --threshold tests/data/recordings/ref3_threshold.json
variant 's/^seed: 1$/seed: 1\nseed: 2/' paper_excitation.yaml dup_scenario.yaml
expect 1 "dup_scenario.yaml:7:1: field 'seed': duplicate key (first given on line 6)" -- "$J" simulate "$W/dup_scenario.yaml" --out "$W/never.csv"
# Friction/threshold JSON: file, line or field named, never nlohmann's "type_error.302" or
# "out_of_range"; a joint number beyond int is not wrapped onto joint 1; width 0 refused.
REPLAY=("$J" replay tests/data/recordings/held_arm.csv --model models/ref3.yaml)
FR=tests/data/recordings/ref3_friction.json
TH=tests/data/recordings/ref3_threshold.json
printf '{"joints": [\n  {"joint": 1, "threshold": 5},\n  {"joint": 2, "threshold": "5"},\n  {"joint": 3, "threshold": 5}]}\n' > "$W/th_text.json"
expect 1 "th_text.json: field 'joints\[1\].threshold': not a number" -- "${REPLAY[@]}" --friction "$FR" --threshold "$W/th_text.json"
printf '{"joints": [\n  {"joint": 4294967297, "threshold": 5},\n  {"joint": 2, "threshold": 5},\n  {"joint": 3, "threshold": 5}]}\n' > "$W/th_big.json"
expect 1 "th_big.json: field 'joints\[0\].joint': not a joint number" -- "${REPLAY[@]}" --friction "$FR" --threshold "$W/th_big.json"
printf '{"joints": [{"joint": 1, "threshold": 5, "low_speed_width": 0}, {"joint": 2, "threshold": 5}, {"joint": 3, "threshold": 5}]}\n' > "$W/th_width.json"
expect 1 "th_width.json: field 'joints\[0\].low_speed_width': must be > 0" -- "${REPLAY[@]}" --friction "$FR" --threshold "$W/th_width.json"
printf '{"joints": 3}\n' > "$W/th_obj.json"
expect 1 "th_obj.json: field 'joints': missing or not a list" -- "${REPLAY[@]}" --friction "$FR" --threshold "$W/th_obj.json"
printf '{"joints": [\n  {"joint": 1,, "sigma0": 1}]}\n' > "$W/fr_syntax.json"
expect 1 "fr_syntax.json:2:[0-9]*: invalid JSON" -- "${REPLAY[@]}" --friction "$W/fr_syntax.json" --threshold "$TH"
printf '{"joints": [{"joint": 1, "threshold": 1e999}]}\n' > "$W/th_huge.json"
expect 1 "th_huge.json: invalid JSON: a number beyond the range of a double" -- "${REPLAY[@]}" --friction "$FR" --threshold "$W/th_huge.json"
! grep -q "json.exception" "$W/err.txt" || { echo "raw nlohmann message"; cat "$W/err.txt"; exit 1; }
# A header naming joint 1 twice (q1 and q01) is refused, not read interleaved.
{ head -1 tests/data/recordings/held_arm.csv | sed 's/$/,q01/'; tail -n +2 tests/data/recordings/held_arm.csv | sed 's/$/,0/'; } > "$W/q01.csv"
expect 1 "q01.csv:1: field 'q01': joint 1 given twice (also 'q1')" -- "$J" replay "$W/q01.csv" --model models/ref3.yaml --friction "$FR" --threshold "$TH"
# An inertia that no body has (not positive semi-definite; a principal moment beyond the sum
# of the other two) is refused naming file, line and field.
sed '17s/{xx: 0.03, yy: 0.03, zz: 0.02}/{xx: 0.03, yy: 0.03, zz: 0.02, xy: 0.5}/' models/ref3.yaml > "$W/npd.yaml"
sed '17s/{xx: 0.03, yy: 0.03, zz: 0.02}/{xx: 0.01, yy: 0.01, zz: 0.05}/' models/ref3.yaml > "$W/moments.yaml"
for m in npd moments; do
  expect 1 "$m.yaml:17:20: field 'joints\[0\].inertia_kg_m2': not the inertia of a body" -- "$J" replay tests/data/recordings/held_arm.csv \
    --model "$W/$m.yaml" --friction "$FR" --threshold "$TH"
done
# A Latin-1 scenario name is refused before the run (it once failed after it, in the JSON
# writer, leaving .csv.tmp and .json.tmp behind).
{ printf 'name: caf\xe9\n'; grep -v '^name:' scenarios/paper_excitation.yaml | sed "s#model: ../models/ref3.yaml#model: $SRC/models/ref3.yaml#"; } > "$W/latin1.yaml"
expect 1 "latin1.yaml:1:7: field 'name': bytes that are not UTF-8 text" -- "$J" simulate "$W/latin1.yaml" --out "$W/never.csv"
! ls "$W"/never* > /dev/null 2>&1 || { echo "a refused scenario left files: $(ls "$W"/never*)"; exit 1; }
# decode: a capture with an undecodable frame exits 1 and writes no JSON; a JSON that cannot
# be written (missing folder) is refused when the command line is read (exit 2), not "exit 0".
printf '(0.000000) vcan0 010##0AA\n' > "$W/short_sync.log"
expect 1 "not written" -- "$J" decode "$W/short_sync.log" --json "$W/never.json"
[ ! -e "$W/never.json" ] || { echo "decode wrote its JSON for an undecodable capture"; exit 1; }
printf '(0.000000) vcan0 010##00000000000000000\n' > "$W/sync.log"
expect 2 "nodir/t.json. does not exist" -- "$J" decode "$W/sync.log" --json "$W/nodir/t.json"
# LuGre parameters the firmware scalar cannot hold (sigma0 1.8e14, as the GA fits on 100 Hz
# data): refused before the run, naming the friction file and the joint, not the recording.
sed 's/98467.9088/1.8e14/' tests/can/hil/friction.json > "$W/huge_sigma0.json"
expect 1 "huge_sigma0.json: joint 1: LuGre parameters (sigma0 180000000000000" -- "$J" replay tests/data/recordings/constant.csv \
  --model models/ref3.yaml --friction "$W/huge_sigma0.json" --threshold tests/data/recordings/ref3_threshold.json --scalar q \
  --json "$W/never.json"
[ ! -e "$W/never.json" ] || { echo "replay wrote its JSON with friction the scalar cannot hold"; exit 1; }
# A robot file carrying the friction an earlier diagnosis identified with its links, and
# --friction beside it: two frictions for one joint, refused naming the file, nothing written.
expect 1 "ref3_friction_baseline.yaml: carries a friction_baseline" -- "$J" diagnose \
  --model tests/fuzz/corpus/robot_yaml/ref3_friction_baseline.yaml --real tests/data/recordings/held_arm.csv \
  --friction tests/data/recordings/ref3_friction.json --json "$W/never.json"
[ ! -e "$W/never.json" ] || { echo "diagnose wrote its JSON with two frictions for one joint"; exit 1; }
echo "bounds: ok"
