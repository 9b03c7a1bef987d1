#!/usr/bin/env bash
# The identity of a result (issue 29 item 2): every JSON the CLI writes carries "identity"
# (version, command, the options that change a figure, the SHA-256 of every input file given),
# the outputs and the split of the work (--json, --out, --jobs, --shard) left out, so the same
# command on the same files gives the same bytes; every command that reads one of these files
# says in one line which version and command wrote it, and warns when the version is not its own.
# Robot files written by `--model-out` carry the same identity as a top-level key `identity`.
# Usage: identity.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
PY=/usr/bin/python3
# Relative paths inside the work folder: the identities name the files as given.
mkdir -p "$W/models" "$W/scenarios" "$W/effects" "$W/out"
cp "$SRC/models/ref3.yaml" "$W/models/"
cp "$SRC/scenarios/paper_excitation.yaml" "$SRC/scenarios/free_motion.yaml" "$SRC/scenarios/paper_collision_shoulder.yaml" "$W/scenarios/"
cp "$SRC/models/effects/ref3_payload.yaml" "$W/effects/"
printf '(1700000000.000000) vcan0 010##10001000000000000\n' > "$W/capture.log"  # one cycle sync (CAN FD)
cd "$W"
M=models/ref3.yaml
fail() { echo "identity: $*"; exit 1; }

"$J" simulate scenarios/paper_excitation.yaml --out exc.csv > /dev/null
"$J" simulate scenarios/free_motion.yaml --out free.csv --duration 20 > /dev/null
"$J" simulate scenarios/paper_collision_shoulder.yaml --out shoulder.csv > /dev/null
"$J" identify exc.csv --model "$M" --runs 2 --gain 150 --json out/f.json > identify.txt
"$J" identify exc.csv --model "$M" --runs 2 --gain 150 --json out/f_again.json > /dev/null
cmp out/f.json out/f_again.json || fail "the same identify into another --json wrote other bytes"
"$J" calibrate free.csv --model "$M" --friction out/f.json --json out/t.json > calibrate.txt
"$J" replay shoulder.csv --model "$M" --friction out/f.json --threshold out/t.json --scalar q --json out/e.json > replay.txt
"$J" identify free.csv --model "$M" --rigid-body --model-out out/m2.yaml --json out/rb.json > /dev/null
"$J" inject free.csv --model "$M" --effects effects/ref3_payload.yaml --out inj.csv > /dev/null
"$J" diagnose --model "$M" --real shoulder.csv --sim shoulder.csv --friction out/f.json --json out/d.json --model-out out/dm.yaml > diagnose.txt
"$J" simulate scenarios/paper_collision_shoulder.yaml --out bus.csv --bus sim --friction out/f.json --threshold out/t.json \
  --json out/bus.json > bus.txt
"$J" decode capture.log --json out/decode.json > /dev/null
S=(--scenario scenarios/paper_collision_shoulder.yaml --free-run 10 --calibration 20 --hold-calibration 20)
"$J" evaluate "${S[@]}" --json out/whole.json > /dev/null
"$J" evaluate "${S[@]}" --shard 1/1 --jobs 2 --json out/part.json > /dev/null
"$J" merge out/part.json --json out/merged.json > merge.txt
cmp out/whole.json out/merged.json || fail "merge of one part is not the unsharded run's bytes"
set +e
"$J" bench --firmware-only --json out/bench.json > /dev/null 2>&1
set -e

# Every JSON written: its identity, the command, the inputs' hashes, no outputs.
"$PY" - "$SRC" <<'PYEOF'
import hashlib, json, os, sys
def sha(p): return hashlib.sha256(open(p, "rb").read()).hexdigest()
M = "models/ref3.yaml"
def ident(path, key=None):
    j = json.load(open(path))
    i = j["jointguard_partial"]["identity"] if key == "partial" else j.get("identity")
    assert isinstance(i, dict), f"{path}: no identity"
    assert i["version"] and i["command"], f"{path}: {i}"
    for o in ("--json", "--out", "--model-out", "--jobs", "--shard"):
        assert o not in i["options"], f"{path}: output or split option {o} in the identity"
    return i
def inputs(path, i, files):
    for f in files:
        assert i["input_sha256"].get(f) == sha(f), f"{path}: input_sha256[{f}] is {i['input_sha256'].get(f)}, the file's is {sha(f)}"
checks = [
    ("exc.json", "simulate", ["scenarios/paper_excitation.yaml"]),
    ("free.json", "simulate", ["scenarios/free_motion.yaml"]),
    ("out/f.json", "identify", ["exc.csv", M]),
    ("out/t.json", "calibrate", ["free.csv", M, "out/f.json"]),
    ("out/e.json", "replay", ["shoulder.csv", M, "out/f.json", "out/t.json"]),
    ("out/rb.json", "identify", ["free.csv", M]),
    ("inj.json", "inject", ["free.csv", M, "effects/ref3_payload.yaml"]),
    ("out/d.json", "diagnose", ["shoulder.csv", M, "out/f.json"]),
    ("out/bus.json", "simulate", ["scenarios/paper_collision_shoulder.yaml", "out/f.json", "out/t.json"]),
    ("bus.json", "simulate", ["scenarios/paper_collision_shoulder.yaml", "out/f.json", "out/t.json"]),
    ("out/decode.json", "decode", ["capture.log"]),
    ("out/whole.json", "evaluate", ["scenarios/paper_collision_shoulder.yaml"]),
    ("out/merged.json", "evaluate", ["scenarios/paper_collision_shoulder.yaml"]),
]
for path, command, files in checks:
    i = ident(path)
    assert i["command"] == command, f"{path}: command {i['command']}, expected {command}"
    inputs(path, i, files)
i = ident("out/f.json")
assert i["options"]["--gain"] == ["150"] and i["options"]["--runs"] == ["2"], i
p = ident("out/part.json", "partial")
assert p == ident("out/whole.json"), "the part's identity is not the whole run's"
assert ident("out/whole.json")["model_sha256"] == sha(M)
n = len(checks) + 1  # and the part
if os.path.exists("out/bench.json"):  # bench --firmware-only writes it when the firmware figures are there
    assert ident("out/bench.json")["command"] == "bench"
    n += 1
print("identity: %d written JSON files carry their identity and the inputs' hashes" % n)
PYEOF

# The readers say what they read: version, command and the file's own hash.
v=$("$PY" -c 'import json; print(json.load(open("out/f.json"))["identity"]["version"])')
fsha=$(sha256sum out/f.json | cut -c1-12)
tsha=$(sha256sum out/t.json | cut -c1-12)
grep -qF "friction: out/f.json (jointguard $v identify, sha256 $fsha)" calibrate.txt || { cat calibrate.txt; fail "calibrate did not report the friction file's identity"; }
grep -qF "friction: out/f.json (jointguard $v identify, sha256 $fsha)" replay.txt || fail "replay: no friction identity line"
grep -qF "threshold: out/t.json (jointguard $v calibrate, sha256 $tsha)" replay.txt || fail "replay: no threshold identity line"
grep -qF "threshold: out/t.json (jointguard $v calibrate" bus.txt || fail "simulate --bus: no threshold identity line"
grep -qF "friction: out/f.json (jointguard $v identify" diagnose.txt || fail "diagnose: no friction identity line"
grep -qF "recording side file: exc.json (jointguard $v simulate" identify.txt || fail "identify: no recording side file identity line"
grep -qF "part: out/part.json (jointguard $v evaluate" merge.txt || fail "merge: no part identity line"

# A file written by another version: a warning naming both versions; the work still runs.
"$PY" - <<'PYEOF'
import json
j = json.load(open("out/f.json"))
j["identity"]["version"] = "0.0.1"
json.dump(j, open("out/f_old.json", "w"), indent=2)
PYEOF
"$J" calibrate free.csv --model "$M" --friction out/f_old.json --json out/t_old.json > old.txt 2> old_err.txt
grep -q "warning: friction out/f_old.json was written by jointguard 0.0.1, this is $v" old_err.txt || { cat old_err.txt; fail "no version warning"; }
grep -qF "friction: out/f_old.json (jointguard 0.0.1 identify" old.txt || fail "no identity line for the old file"
# Its own version: no warning.
! grep -q "warning: friction" <("$J" calibrate free.csv --model "$M" --friction out/f.json --json out/t2.json 2>&1 >/dev/null) ||
  fail "a version warning for a file of this version"
# A file without identity (written by hand): said so, no warning.
"$PY" -c 'import json; j = json.load(open("out/f.json")); j.pop("identity"); json.dump(j, open("out/f_hand.json", "w"))'
"$J" calibrate free.csv --model "$M" --friction out/f_hand.json --json out/t3.json > hand.txt 2> hand_err.txt
grep -q "friction: out/f_hand.json (no identity" hand.txt || fail "no line for a file without identity"
! grep -q "warning: friction" hand_err.txt || fail "a version warning for a file without identity"

# Robot files written by --model-out carry the same identity (a top-level key `identity`),
# the robot reader takes it, and every command that loads one says what wrote it.
"$PY" - "$SRC" <<'PYEOF'
import hashlib, json, sys
import yaml  # an independent YAML reader: the key must be plain YAML, not jointguard's dialect
def sha(p): return hashlib.sha256(open(p, "rb").read()).hexdigest()
M = "models/ref3.yaml"
for path, command, files, twin in [("out/m2.yaml", "identify", ["free.csv", M], "out/rb.json"),
                                   ("out/dm.yaml", "diagnose", ["shoulder.csv", M, "out/f.json"], "out/d.json")]:
    i = yaml.safe_load(open(path)).get("identity")
    assert isinstance(i, dict), f"{path}: no identity key"
    assert i["command"] == command and i["version"], f"{path}: {i}"
    for o in ("--json", "--model-out", "--jobs"):
        assert o not in i["options"], f"{path}: output option {o} in the identity"
    for f in files:
        assert i["input_sha256"].get(f) == sha(f), f"{path}: input_sha256[{f}] is {i['input_sha256'].get(f)}, the file's is {sha(f)}"
    assert i == json.load(open(twin))["identity"], f"{path}: identity differs from the JSON of the same run ({twin})"
print("identity: --model-out robot files carry the identity of the run that wrote them")
PYEOF
m2sha=$(sha256sum out/m2.yaml | cut -c1-12)
"$J" simulate scenarios/paper_collision_shoulder.yaml --model out/m2.yaml --out s_m2.csv > m2.txt 2> m2_err.txt
grep -qF "robot file: out/m2.yaml (jointguard $v identify, sha256 $m2sha)" m2.txt || { cat m2.txt; fail "simulate --model did not report the robot file's identity"; }
[ "$(grep -c 'robot file: out/m2.yaml' m2.txt)" = 1 ] || fail "the robot file's identity reported more than once"
! grep -q "warning: robot file" m2_err.txt || fail "a version warning for a robot file of this version"
"$J" diagnose --model out/dm.yaml --real shoulder.csv --sim shoulder.csv --json out/d2.json > dm.txt
grep -qF "robot file: out/dm.yaml (jointguard $v diagnose" dm.txt || fail "diagnose --model did not report the robot file's identity"
! grep -q "robot file: $M" replay.txt || fail "a hand-written robot file (no identity) reported as written by jointguard"
# Another version: a warning naming both; no identity mapping: refused naming file, line and field.
sed "s/^  \"version\": \"$v\"/  \"version\": \"0.0.1\"/" out/m2.yaml > out/m2_old.yaml
grep -q '"version": "0.0.1"' out/m2_old.yaml || fail "test setup: the version line not found in out/m2.yaml"
"$J" simulate scenarios/paper_collision_shoulder.yaml --model out/m2_old.yaml --out s_old.csv > /dev/null 2> m2_old_err.txt
grep -q "warning: robot file out/m2_old.yaml was written by jointguard 0.0.1, this is $v" m2_old_err.txt || { cat m2_old_err.txt; fail "no version warning for an old robot file"; }
{ cat "$M"; echo "identity: 5"; } > models/bad_identity.yaml
set +e
"$J" simulate scenarios/paper_collision_shoulder.yaml --model models/bad_identity.yaml --out s_bad.csv > /dev/null 2> bad_err.txt
rc=$?
set -e
[ "$rc" = 1 ] || fail "a robot file whose identity is not a mapping: exit $rc, expected 1"
grep -Eq "models/bad_identity.yaml:[0-9]+:[0-9]+: field 'identity': expected a mapping" bad_err.txt || { cat bad_err.txt; fail "the refusal does not name file, line and field"; }
echo "identity: every JSON and robot file written carries its identity; readers report it and warn on another version"
