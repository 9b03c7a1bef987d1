#!/usr/bin/env bash
# jointguard pipeline (issue 31 item 2): identify -> calibrate -> replay -> report in one
# command, on a user's recordings.
#  (a) simulated reference arm (jointguard simulate): the folder holds friction.json,
#      threshold.json, one replay JSON per recording, report.html and pipeline.json; the
#      report names the detection; the step files equal those of identify, calibrate and
#      replay run by hand with the same options, apart from "identity"; without --calibrate
#      it calibrates on the identification recording and says so (a warning, pipeline.json).
#  (b) real UR10e at the defaults (skipped without ../shared/data/real): identify and
#      calibrate on motion_free, replay static_pushes and motion_free: every push detected,
#      no event outside the pushes, none on motion_free (ur10e_pushes.py).
#  (c) bad input: command-line errors exit 2 naming the option or file; a work error exits 1
#      naming the file and leaves no output behind, even after identify had finished.
# Usage: pipeline.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
PY=/usr/bin/python3
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
M="$SRC/models/ref3.yaml"
fail() { echo "FAILED: $*"; exit 1; }

# ---- (a) simulated arm: the pipeline against the three commands by hand -----------------
sed -e "s#\.\./models#$SRC/models#" -e 's/^duration_s: 60/duration_s: 20/' "$SRC/scenarios/calibration_motion.yaml" > "$W/ident.yaml"
sed -e "s#\.\./models#$SRC/models#" -e 's/^duration_s: 60/duration_s: 20/' -e 's/seed: 5/seed: 9/' \
  "$SRC/scenarios/calibration_motion.yaml" > "$W/free.yaml"
"$J" simulate "$W/ident.yaml" --out "$W/ident.csv" > /dev/null
"$J" simulate "$W/free.yaml" --out "$W/free.csv" > /dev/null
"$J" simulate "$SRC/scenarios/paper_collision_shoulder.yaml" --out "$W/shoulder.csv" > /dev/null
OPT=(--model "$M" --runs 2)
"$J" pipeline "${OPT[@]}" --identify "$W/ident.csv" --calibrate "$W/free.csv" "$W/shoulder.csv" "$W/free.csv" \
  --out "$W/pipe" > "$W/pipe.txt" || { cat "$W/pipe.txt"; fail "pipeline on the simulated arm"; }
H="$W/hand"
mkdir "$H"
"$J" identify "$W/ident.csv" "${OPT[@]}" --json "$H/friction.json" > /dev/null
"$J" calibrate "$W/free.csv" --model "$M" --friction "$H/friction.json" --json "$H/threshold.json" > /dev/null
for rec in shoulder free; do
  "$J" replay "$W/$rec.csv" --model "$M" --friction "$H/friction.json" --threshold "$H/threshold.json" \
    --json "$H/replay_$rec.json" > /dev/null
done
"$PY" - "$W" <<'PYEOF'
import json, os, sys
w = sys.argv[1]
pipe, hand = f"{w}/pipe", f"{w}/hand"
names = ["friction.json", "threshold.json", "replay_shoulder.json", "replay_free.json"]
for f in names + ["report.html", "pipeline.json"]:
    assert os.path.isfile(f"{pipe}/{f}"), f"pipeline did not write {f}"
assert not [f for f in os.listdir(pipe) if f.startswith(".")], f"partial files left: {os.listdir(pipe)}"
def strip(d):
    return {k: v for k, v in d.items() if k != "identity"}
for f in names:
    a, b = json.load(open(f"{pipe}/{f}")), json.load(open(f"{hand}/{f}"))
    assert a["identity"]["command"] == "pipeline", (f, a["identity"])
    if strip(a) != strip(b):
        diff = [k for k in set(a) | set(b) if k != "identity" and a.get(k) != b.get(k)]
        raise SystemExit(f"FAILED: {f}: the pipeline's differs from the command's by hand in {diff}")
    print(f"{f}: as by hand")
s = json.load(open(f"{pipe}/pipeline.json"))
ident = s["identity"]
assert ident["command"] == "pipeline" and ident["version"], ident
assert any(k.endswith("ident.csv") for k in ident["input_sha256"]), ident["input_sha256"]
assert "--out" not in ident["options"], ident["options"]
ev = json.load(open(f"{pipe}/replay_shoulder.json"))["events"]
# The paper's shoulder collision at 5.872 s on link 2.
assert len(ev) == 1 and 5.872 < ev[0]["t"] < 5.872 + 0.05 and ev[0]["link"] == 2, ev
free = json.load(open(f"{pipe}/replay_free.json"))["events"]
assert s["summary"] == {"recordings": 2, "events": 1 + len(free)}, s["summary"]
assert s["calibration"]["source"] == "--calibrate" and not s["warnings"], s["calibration"]
html = open(f"{pipe}/report.html").read()
assert "shoulder.csv: 1 detection(s)" in html and f"{ev[0]['t']:.4f}" in html and "<svg" in html, "report lacks the detection"
print(f"shoulder collision detected at {ev[0]['t']:.4f} s, link {ev[0]['link']}; free motion (calibrated on it): {len(free)} events")
PYEOF
grep -q "shoulder.csv (replay_shoulder.json): 1 detection(s)" "$W/pipe.txt" || { cat "$W/pipe.txt"; fail "console summary"; }
# Without --calibrate: the identification recording, with a warning that says why it may be optimistic.
"$J" pipeline --model "$M" --runs 1 --identify "$W/ident.csv" "$W/shoulder.csv" --out "$W/nocal" > "$W/nocal.txt"
grep -q "warning: no --calibrate recording: the thresholds are calibrated on the identification recording .*ident.csv.* may be optimistic" \
  "$W/nocal.txt" || { cat "$W/nocal.txt"; fail "no warning without --calibrate"; }
"$PY" -c 'import json,sys; s=json.load(open(sys.argv[1])); assert s["calibration"]["recording"].endswith("ident.csv") and s["warnings"], s["calibration"]' \
  "$W/nocal/pipeline.json"

# ---- (c) bad input ------------------------------------------------------------------------
expect() {  # expect CODE PATTERN ARGS...: exit code CODE and PATTERN in the output
  local code="$1" pattern="$2" rc=0
  shift 2
  "$J" pipeline "$@" > "$W/bad.txt" 2>&1 || rc=$?
  [ "$rc" = "$code" ] || { cat "$W/bad.txt"; fail "exit $rc (wanted $code): pipeline $*"; }
  grep -q -- "$pattern" "$W/bad.txt" || { cat "$W/bad.txt"; fail "no '$pattern' in the message: pipeline $*"; }
}
expect 2 "--identify is required" --model "$M" "$W/shoulder.csv" --out "$W/x"
expect 2 "recordings is required" --model "$M" --identify "$W/ident.csv" --out "$W/x"
expect 2 "no_such.csv" --model "$M" --identify "$W/ident.csv" "$W/no_such.csv" --out "$W/x"
expect 2 "--out: '$W/ident.csv' is a file, not a folder" --model "$M" --identify "$W/ident.csv" "$W/shoulder.csv" --out "$W/ident.csv"
expect 2 "--scalar" --model "$M" --identify "$W/ident.csv" "$W/shoulder.csv" --out "$W/x" --scalar double
[ ! -e "$W/x" ] || fail "a refused command line created --out"
# A replay recording that is not one: refused before any work, naming it; nothing written.
printf 't,q1,dq1\n0,0,0\n' > "$W/broken.csv"
expect 1 "broken.csv" --model "$M" --identify "$W/ident.csv" "$W/broken.csv" --out "$W/x"
[ ! -e "$W/x" ] || fail "a refused recording left $(ls -A "$W/x")"
# A calibration recording too short to calibrate on: found after identify wrote its file;
# the folder keeps nothing of the run (an existing folder keeps what it had).
head -301 "$W/free.csv" > "$W/short.csv"
mkdir "$W/y" && echo keep > "$W/y/mine.txt"
expect 1 "short.csv" --model "$M" --runs 1 --identify "$W/ident.csv" --calibrate "$W/short.csv" "$W/shoulder.csv" --out "$W/y"
[ "$(ls -A "$W/y")" = mine.txt ] || fail "a failed run left $(ls -A "$W/y")"
echo "bad input: refused as expected"

# ---- (b) the real UR10e at the defaults ---------------------------------------------------
U="$SRC/../shared/data/real/ur10e-static"
if [ ! -f "$U/motion_free.csv" ] || [ ! -f "$U/ur10e.urdf" ]; then
  echo "skipped: real recordings not found in $U (parts a and c passed)"
  exit 77
fi
"$J" pipeline --model "$U/ur10e.urdf" --drive "$U/drive.yaml" --identify "$U/motion_free.csv" \
  "$U/static_pushes.csv" "$U/motion_free.csv" --out "$W/ur" > "$W/ur.txt" || { cat "$W/ur.txt"; fail "pipeline on the UR10e"; }
grep "detection(s)" "$W/ur.txt"
cd "$SRC/tests/cli"
"$PY" ur10e_pushes.py "$U" "$W/ur/replay_static_pushes.json" "$W/ur/replay_motion_free.json" ||
  fail "UR10e at the defaults: a push missed or a false alarm"
