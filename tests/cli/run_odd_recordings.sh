#!/usr/bin/env bash
# Odd recordings (tests/data/recordings/, made by make_recordings.py there) through every
# subcommand that reads one: exit 0 with a complete JSON that says which torque it used
# and how it resampled, or exit 1 with a message naming the file and nothing written;
# never a crash. Usage: run_odd_recordings.sh <jointguard> <source dir>
set -uo pipefail
J="$1"
SRC="$2"
D="$SRC/tests/data/recordings"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
fail=0
bad() { echo "FAIL: $*"; fail=1; }

# expect: ok (exit 0 required), refuse (exit 1 required) or any (0 or 1).
check() {
  local file="$1" cmd="$2" expect="$3"
  shift 3
  local base
  base=$(basename "$file" .csv)
  local out="$W/$base.$cmd.json"
  "$J" "$cmd" "$@" --json "$out" > "$W/stdout" 2> "$W/stderr"
  local rc=$?
  case "$rc" in
    0)
      [ "$expect" != refuse ] || bad "$base $cmd: exit 0, expected a refusal"
      [ -s "$out" ] || { bad "$base $cmd: exit 0 without its JSON"; return; }
      grep -q '"torque": "\(i\|tau_m\|tau_j\)"' "$out" || bad "$base $cmd: JSON without \"torque\""
      grep -q '"resampling"' "$out" || bad "$base $cmd: JSON without \"resampling\""
      grep -qi 'nan\|inf' "$out" && bad "$base $cmd: non-finite number in the JSON"
      if command -v python3 > /dev/null; then
        python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$out" || bad "$base $cmd: JSON does not parse"
      fi
      grep -q "^torque: " "$W/stdout" || bad "$base $cmd: no line saying which torque was used"
      ;;
    1)
      [ "$expect" != ok ] || { bad "$base $cmd: exit 1, expected success"; cat "$W/stderr"; }
      grep -q "$base" "$W/stderr" || { bad "$base $cmd: the message must name the file"; cat "$W/stderr"; }
      [ ! -e "$out" ] || bad "$base $cmd: exit 1 but $out was written"
      ;;
    *)
      bad "$base $cmd: exit $rc (crash?)"
      cat "$W/stderr"
      ;;
  esac
  ls "$W"/*.tmp > /dev/null 2>&1 && bad "$base $cmd: a temporary file was left behind"
  return 0
}

run_all() {
  local file="$1" model="$2" fr="$3" th="$4" expect_diag="$5" expect_rest="$6"
  check "$file" diagnose "$expect_diag" --model "$model" --real "$file"
  check "$file" identify "$expect_rest" "$file" --model "$model" --runs 1
  check "$file" calibrate "$expect_rest" "$file" --model "$model" --friction "$fr"
  check "$file" replay "$expect_rest" "$file" --model "$model" --friction "$fr" --threshold "$th"
}

R3=models/ref3.yaml
F3="$D/ref3_friction.json"
T3="$D/ref3_threshold.json"
run_all "$D/held_arm.csv" "$R3" "$F3" "$T3" ok any
run_all "$D/one_joint_moving.csv" "$R3" "$F3" "$T3" ok any
run_all "$D/constant.csv" "$R3" "$F3" "$T3" any any
run_all "$D/single_sample.csv" "$R3" "$F3" "$T3" refuse refuse
run_all "$D/two_samples.csv" "$R3" "$F3" "$T3" refuse refuse
run_all "$D/irregular_gap.csv" "$R3" "$F3" "$T3" ok any
run_all "$D/shoulder_first_0.2s.csv" "$R3" "$F3" "$T3" ok any
run_all "$D/seven_joint_tau_j.csv" models/panda.yaml "$D/panda_friction.json" "$D/panda_threshold.json" ok any

# What the tool says it did.
"$J" diagnose --model "$R3" --real "$D/irregular_gap.csv" --json "$W/irr.json" > "$W/irr.txt" 2>&1 || bad "irregular_gap diagnose failed"
grep -q "^resampled irregular_gap.csv: .* rows -> .* at 200 Hz, linear by time stamp; [1-9][0-9]* repeated rows dropped; .* 1 gaps split" "$W/irr.txt" ||
  { bad "irregular_gap: resampling line"; cat "$W/irr.txt"; }
grep -q "diagnosis over all 2 segments" "$W/irr.txt" || bad "irregular_gap: both segments must be diagnosed"
"$J" replay "$D/seven_joint_tau_j.csv" --model models/panda.yaml --friction "$D/panda_friction.json" \
  --threshold "$D/panda_threshold.json" --json "$W/seven.json" > "$W/seven.txt" 2>&1 || bad "seven_joint replay failed"
grep -q "^torque: tau_j" "$W/seven.txt" || bad "seven_joint: must say it used tau_j"
grep -q "uniform: used as recorded" "$W/seven.txt" || bad "seven_joint: a uniform recording is used as recorded"
# --torque-kind: a tau_m column re-read as a joint torque sensor; a kind the file lacks is refused.
"$J" diagnose --model "$R3" --real "$D/held_arm.csv" --torque-kind motor > "$W/tk.txt" 2>&1
[ $? = 1 ] || bad "--torque-kind motor on a current-only file must be refused"
grep -q "held_arm.csv:1: field 'tau_m1'" "$W/tk.txt" || { bad "--torque-kind motor: message"; cat "$W/tk.txt"; }
"$J" diagnose --model "$R3" --real "$D/shoulder_first_0.2s.csv" --torque-kind joint --json "$W/tj.json" > "$W/tj.txt" 2>&1 ||
  bad "--torque-kind joint on tau_m columns failed"
grep -q '"torque": "tau_j"' "$W/tj.json" || bad "--torque-kind joint: JSON must say tau_j"
# An output into a missing folder or onto a folder: refused when the command line is read
# (exit 2 comes only from the command line's parser, so before any work, the option named);
# no "wrote", nothing written.
for c in replay calibrate diagnose identify bench simulate evaluate decode; do
  case $c in
    replay) args=("$D/held_arm.csv" --model "$R3" --friction "$F3" --threshold "$T3") ;;
    calibrate) args=("$D/held_arm.csv" --model "$R3" --friction "$F3") ;;
    diagnose) args=(--model "$R3" --real "$D/held_arm.csv") ;;
    identify) args=("$D/held_arm.csv" --model "$R3") ;;
    bench) args=(--firmware-only) ;;
    simulate) args=(scenarios/paper_collision_shoulder.yaml --out "$W/s.csv" --bus sim --threshold "$T3") ;;
    evaluate) args=(--scenario paper) ;;
    decode) printf '(0.000000) vcan0 010#00\n' > "$W/cap.log"; args=("$W/cap.log") ;;
  esac
  for target in "$W/no/such/dir/e.json" "$W"; do
    "$J" "$c" "${args[@]}" --json "$target" > "$W/nd.txt" 2>&1
    rc=$?
    [ $rc = 2 ] || { bad "$c --json $target must be refused as a bad command line (got $rc)"; cat "$W/nd.txt"; }
    grep -q -- "--json: " "$W/nd.txt" || { bad "$c --json $target: the message must name the option"; cat "$W/nd.txt"; }
    grep -q "^wrote" "$W/nd.txt" && bad "$c --json $target must not say wrote"
  done
done
# A recording's missing folders are created (the README's first command writes into out/);
# a file standing where a folder must be is refused before the run.
"$J" simulate scenarios/paper_collision_shoulder.yaml --duration 0.2 --out "$W/new/dir/s.csv" > "$W/nd.txt" 2>&1 ||
  bad "simulate --out into folders still to be made must create them"
[ -s "$W/new/dir/s.csv" ] && [ -s "$W/new/dir/s.json" ] || bad "simulate --out: no recording in the new folders"
touch "$W/a_file"
"$J" simulate scenarios/paper_collision_shoulder.yaml --duration 0.2 --out "$W/a_file/s.csv" > "$W/nd.txt" 2>&1
[ $? = 2 ] && grep -q -- "--out: '.*a_file' in '.*' is a file, not a folder" "$W/nd.txt" || { bad "simulate --out through a file must be refused"; cat "$W/nd.txt"; }

# Friction and threshold files are matched by joint number, not by position.
python3 - "$F3" "$W/fr_ordered.json" "$W/fr_reversed.json" "$W/fr_two.json" <<'PY' || bad "could not write the friction variants"
import json, sys
j = json.load(open(sys.argv[1]))
j["joints"][0]["tau_c"] = 3.0  # joint 1 differs from the others: the order matters
json.dump(j, open(sys.argv[2], "w"))
json.dump({"joints": j["joints"][::-1]}, open(sys.argv[3], "w"))
json.dump({"joints": j["joints"][:2]}, open(sys.argv[4], "w"))
PY
"$J" calibrate "$D/one_joint_moving.csv" --model "$R3" --friction "$W/fr_ordered.json" --json "$W/c1.json" > /dev/null 2>&1 || bad "calibrate, ordered friction"
"$J" calibrate "$D/one_joint_moving.csv" --model "$R3" --friction "$W/fr_reversed.json" --json "$W/c2.json" > /dev/null 2>&1 || bad "calibrate, reversed friction"
# The same thresholds; the identities differ (they name the two friction files and their hashes).
/usr/bin/python3 -c 'import json,sys; a,b=(json.load(open(p)) for p in sys.argv[1:3]); a.pop("identity"); b.pop("identity"); sys.exit(a != b)' \
  "$W/c1.json" "$W/c2.json" || bad "friction entries listed 3,2,1 must give the same thresholds as 1,2,3"
"$J" calibrate "$D/one_joint_moving.csv" --model "$R3" --friction "$W/fr_two.json" --json "$W/c3.json" > "$W/c3.txt" 2>&1
[ $? = 1 ] || bad "2 friction entries for 3 joints must be refused"
grep -q "fr_two.json: field 'joints': 2 entries" "$W/c3.txt" || { bad "friction count: message"; cat "$W/c3.txt"; }
[ ! -e "$W/c3.json" ] || bad "a refused calibration wrote its JSON"

[ "$fail" = 0 ] && echo "odd recordings OK"
exit "$fail"
