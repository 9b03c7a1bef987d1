#!/usr/bin/env bash
# The recording's JSON side file (issue 29): `simulate --out run.csv` overwrote an existing
# run.json silently; an unrelated mydata.json beside mydata.csv made the CSV unreadable
# ("field 'model': wrong type"); `simulate --out rec.json` left rec.json holding only the
# metadata. Now another program's <name>.json is ignored with a note when reading and never
# overwritten (exit 1, nothing written), and a recording's --out ending in .json is refused
# (exit 2).
# Usage: side_file.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
run() {  # run RC -- command...: exit code RC, stdout/stderr in $W/out.txt, $W/err.txt
  local want="$1"
  shift 2
  set +e
  timeout 120 "$@" > "$W/out.txt" 2> "$W/err.txt"
  local rc=$?
  set -e
  [ "$rc" = "$want" ] || { echo "expected exit $want from: $*; got $rc"; cat "$W/err.txt"; exit 1; }
}
SIM=("$J" simulate scenarios/free_motion.yaml --duration 0.05)
FOREIGN='{"model": {"layers": 3}, "note": "written by another program"}'

# Writing: another program's run.json is kept, and nothing is written.
echo "$FOREIGN" > "$W/run.json"
run 1 -- "${SIM[@]}" --out "$W/run.csv"
grep -q "run.json: the recording's side file would overwrite a file that is not jointguard's" "$W/err.txt" || { cat "$W/err.txt"; exit 1; }
[ "$(cat "$W/run.json")" = "$FOREIGN" ] || { echo "run.json was changed"; exit 1; }
[ ! -e "$W/run.csv" ] || { echo "run.csv written although refused"; exit 1; }
# Our own side file is replaced (a second run over the first).
rm "$W/run.json"
run 0 -- "${SIM[@]}" --seed 1 --out "$W/run.csv"
run 0 -- "${SIM[@]}" --seed 2 --out "$W/run.csv"
grep -q '"seed": 2' "$W/run.json" || { echo "our side file not replaced"; cat "$W/run.json"; exit 1; }
grep -q '"format": "jointguard-recording"' "$W/run.json" || { echo "no format key"; exit 1; }

# Reading: an unrelated mydata.json is ignored with a note; the CSV is read.
cp "$W/run.csv" "$W/mydata.csv"
echo "$FOREIGN" > "$W/mydata.json"
printf 'plant_effects: []\n' > "$W/none.yaml"
run 0 -- "$J" inject "$W/mydata.csv" --model models/ref3.yaml --effects "$W/none.yaml" --out "$W/copy.csv"
grep -q "note: .*mydata.json is not a jointguard side file" "$W/err.txt" || { echo "no note"; cat "$W/err.txt"; exit 1; }
cmp -s "$W/mydata.csv" "$W/copy.csv" || { echo "copy differs"; exit 1; }
# inject's own side file is one of ours: reading its output gives no note.
run 0 -- "$J" inject "$W/copy.csv" --model models/ref3.yaml --effects "$W/none.yaml" --out "$W/copy2.csv"
if grep -q "not a jointguard side file" "$W/err.txt"; then echo "inject's side file taken for another program's"; cat "$W/err.txt"; exit 1; fi
# inject does not overwrite another program's side file either.
echo "$FOREIGN" > "$W/copy3.json"
run 1 -- "$J" inject "$W/run.csv" --model models/ref3.yaml --effects "$W/none.yaml" --out "$W/copy3.csv"
grep -q "copy3.json: the recording's side file would overwrite" "$W/err.txt" || { cat "$W/err.txt"; exit 1; }
[ "$(cat "$W/copy3.json")" = "$FOREIGN" ] && [ ! -e "$W/copy3.csv" ] || { echo "inject wrote over copy3.json"; exit 1; }

# --out with a .json name: refused before any work.
run 2 -- "${SIM[@]}" --out "$W/rec.json"
grep -q "ends in .json: a recording is a CSV file" "$W/err.txt" || { cat "$W/err.txt"; exit 1; }
[ ! -e "$W/rec.json" ] || { echo "rec.json written"; exit 1; }
run 2 -- "${SIM[@]}" --out "$W/REC.JSON"
echo "side_file: ok"
