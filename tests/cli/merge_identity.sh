#!/usr/bin/env bash
# Parts that merge are parts of one result (issue 29): every option given, the inputs'
# content and the version are the parts' identity, and merge names the first difference;
# a safety scenario's ISO/TS 15066 verdict survives the merge (byte-identical to the
# unsharded run); --scenario safety is not sharded (exit 2); merge never overwrites one of
# its parts (exit 2) and refuses absurd counts in a part before acting on them (exit 1).
# Usage: merge_identity.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
PY=/usr/bin/python3
S=(--scenario scenarios/iso_hand_clamp.yaml --free-run 10 --calibration 20 --hold-calibration 20)
"$J" evaluate "${S[@]}" --json "$W/whole.json" > /dev/null
"$J" evaluate "${S[@]}" --shard 1/1 --json "$W/part.json" > /dev/null
"$J" merge "$W/part.json" --json "$W/merged.json" > /dev/null
grep -q '"safety"' "$W/whole.json"
cmp "$W/whole.json" "$W/merged.json"
# Two halves made with another option: refused, naming it.
"$J" evaluate "${S[@]}" --shard 1/2 --contact-prior-friction 0.5 --json "$W/a.json" > /dev/null
"$J" evaluate "${S[@]}" --shard 2/2 --contact-prior-friction 2.0 --json "$W/b.json" > /dev/null
set +e
"$J" merge "$W/a.json" "$W/b.json" --json "$W/ab.json" 2> "$W/err"; rc=$?
set -e
[ "$rc" -eq 1 ] && grep -q -- "--contact-prior-friction" "$W/err" || { echo "merge of parts with other options: exit $rc"; cat "$W/err"; exit 1; }
[ ! -e "$W/ab.json" ]
# The identity holds the version and the model file's content.
"$PY" - "$W/a.json" <<'PYEOF'
import json, sys
i = json.load(open(sys.argv[1]))["jointguard_partial"]["identity"]
assert i["version"] and len(i["model_sha256"]) == 64, i
assert i["options"]["--contact-prior-friction"] == ["0.5"], i
assert "--shard" not in i["options"] and "--json" not in i["options"], i
PYEOF
expect() {  # expect RC PATTERN CMD...
  local want="$1" pat="$2"
  shift 2
  set +e
  "$@" > /dev/null 2> "$W/err"
  local rc=$?
  set -e
  [ "$rc" -eq "$want" ] && grep -q -- "$pat" "$W/err" || { echo "$*: exit $rc (expected $want, '$pat')"; cat "$W/err"; exit 1; }
}
expect 2 "not split into parts" "$J" evaluate --scenario safety --shard 2/2 --json "$W/s.json"
expect 2 "one of the parts" "$J" merge "$W/part.json" --json "$W/part.json"
"$PY" - "$W/part.json" "$W/huge.json" "$W/index.json" <<'PYEOF'
import json, sys
p = json.load(open(sys.argv[1]))
p["jointguard_partial"]["shards"] = 2000000000
json.dump(p, open(sys.argv[2], "w"))
p = json.load(open(sys.argv[1]))
p["runs"][0]["index"] = 1e300
json.dump(p, open(sys.argv[3], "w"))
PYEOF
expect 1 "field 'shards'" "$J" merge "$W/huge.json" --json "$W/x.json"
expect 1 "runs\[\].index" "$J" merge "$W/index.json" --json "$W/x.json"
echo "merge_identity: ok"
