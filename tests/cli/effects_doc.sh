#!/usr/bin/env bash
# The effect catalogue in docs/diagnosis.md is `jointguard effects`'s output (one table in the
# code, robot/effect_catalogue.cpp; the docs show it), and `--json` writes every row.
# Usage: effects_doc.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
"$J" effects > "$W/table.txt"
"$J" effects --json "$W/effects.json" > /dev/null
sed -n '/<!-- effects:begin/,/<!-- effects:end/p' "$SRC/docs/diagnosis.md" | sed '1d;$d' > "$W/doc.txt"
if ! diff -u "$W/doc.txt" "$W/table.txt"; then
  echo "docs/diagnosis.md's effect catalogue differs from 'jointguard effects' (above): paste the command's output between the markers"
  exit 1
fi
rows=$(grep -c '^| `' "$W/table.txt")
[ "$rows" -ge 16 ] || { echo "expected 16 effects in the table, got $rows"; exit 1; }
/usr/bin/python3 - "$W/effects.json" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["effects"]
names = [r["effect"] for r in rows]
assert names[-1] == "none" and len(set(names)) == len(names) == 17, names
assert [r["number"] for r in rows] == list(range(17))
assert {r["effect"] for r in rows if r["scope"] == "arm"} == {"payload", "link_inertial_error"}
PY
echo "effects_doc: the docs' catalogue is the command's ($rows effects), the JSON has every row"
