#!/usr/bin/env bash
# Two `simulate` runs writing the same --out at once (issue 29: both used <out>.tmp; one
# printed "wrote same.csv" over a file mixing both runs, the other failed on the rename and
# left same.json.tmp). Each pair must leave one complete recording, the CSV and its side
# file from the same run, each run exiting 0 or refusing clearly (exit 1), and no temporary
# file. PAIRS pairs (default 100; CI passes fewer, docs/recordings.md gives the full command).
# Usage: concurrent_out.sh <jointguard> <source dir> [PAIRS]
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
PAIRS="${3:-100}"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
# The shortest runs that still write real files, of different lengths and seeds: the row
# count tells which run the CSV is from, the seed in the side file which run that is from.
A_S=0.05 B_S=0.08 A_ROWS=51 B_ROWS=81
printf 'plant_effects: []\n' > "$W/none.yaml"
for p in $(seq 1 "$PAIRS"); do
  "$J" simulate scenarios/free_motion.yaml --duration $A_S --seed 1 --out "$W/same.csv" > "$W/a.out" 2> "$W/a.err" &
  pa=$!
  "$J" simulate scenarios/free_motion.yaml --duration $B_S --seed 2 --out "$W/same.csv" > "$W/b.out" 2> "$W/b.err" &
  pb=$!
  set +e
  wait $pa; ra=$?
  wait $pb; rb=$?
  set -e
  for r in a:$ra b:$rb; do
    rc=${r#*:}
    if [ "$rc" != 0 ] && { [ "$rc" != 1 ] || ! grep -q "error:" "$W/${r%%:*}.err"; }; then
      echo "pair $p: run ${r%%:*} exited $rc without a clear refusal"; cat "$W/${r%%:*}.err"; exit 1
    fi
  done
  [ "$ra" = 0 ] || [ "$rb" = 0 ] || { echo "pair $p: both runs failed"; cat "$W/a.err" "$W/b.err"; exit 1; }
  rows=$(($(wc -l < "$W/same.csv") - 1))
  # Complete: every row has the header's field count and ends in a newline.
  awk -F, 'NR == 1 { n = NF } NF != n { bad = 1 } END { exit bad }' "$W/same.csv" || { echo "pair $p: ragged rows"; exit 1; }
  [ "$(tail -c 1 "$W/same.csv" | od -An -c | tr -d ' ')" = '\n' ] || { echo "pair $p: last row cut"; exit 1; }
  seed=$(sed -n 's/.*"seed": *\([0-9]*\).*/\1/p' "$W/same.json")
  case "$rows:$seed" in
    "$A_ROWS:1") [ "$ra" = 0 ] || { echo "pair $p: run a's file but run a failed"; exit 1; } ;;
    "$B_ROWS:2") [ "$rb" = 0 ] || { echo "pair $p: run b's file but run b failed"; exit 1; } ;;
    *) echo "pair $p: $rows rows with the side file of seed '$seed': a mix of the two runs"; exit 1 ;;
  esac
  # Readable back through the recording reader (a copy through inject with no effects).
  "$J" inject "$W/same.csv" --model models/ref3.yaml --effects "$W/none.yaml" --out "$W/back/copy.csv" > /dev/null 2> "$W/back.err" ||
    { echo "pair $p: the recording does not read back"; cat "$W/back.err"; exit 1; }
  leftovers=$(find "$W" -name '*.tmp*' | wc -l)
  [ "$leftovers" = 0 ] || { echo "pair $p: temporary files left:"; find "$W" -name '*.tmp*'; exit 1; }
done
echo "concurrent_out: $PAIRS pairs, each one complete recording"
