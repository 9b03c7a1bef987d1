#!/usr/bin/env bash
# Campaigns on every core and in parts (issue 18): the same campaign with --jobs 1, with
# --jobs 2, in two shards merged, and in three shards run by GNU parallel
# (scripts/cluster/parallel_campaign.sh) must give byte-identical JSON; a merge with a part
# missing or given twice fails (exit 1) and writes nothing.
# Usage: scale.sh JOINTGUARD SOURCE_DIR
set -euo pipefail
J="$1"
SRC="$2"
T="$(mktemp -d)"
trap 'rm -rf "${T}"' EXIT
# Small but complete: 5 collisions, a free run of two segments (700 s), both calibrations
# in two segments each (600 s + 10 s: the segments run over the threads and merge).
args=(--scenario campaign --count 5 --free-run 700 --calibration 610 --hold-calibration 610)
"${J}" evaluate "${args[@]}" --jobs 1 --json "${T}/jobs1.json" > "${T}/jobs1.log"
"${J}" evaluate "${args[@]}" --jobs 2 --json "${T}/jobs2.json" > /dev/null
cmp "${T}/jobs1.json" "${T}/jobs2.json"
python3 - "${T}/jobs1.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
assert len(j["runs"]) == 5, len(j["runs"])
assert [r["index"] for r in j["runs"]] == list(range(5))
assert j["summary"]["false_alarm_run_s"] == 700 and j["summary"]["false_alarm_segments"] == 2
PY
for k in 1 2; do
  "${J}" evaluate "${args[@]}" --shard "${k}/2" --json "${T}/part${k}.json" > /dev/null
done
"${J}" merge "${T}/part2.json" "${T}/part1.json" --json "${T}/merged.json" > /dev/null
cmp "${T}/jobs1.json" "${T}/merged.json"
# Bad merges: exit 1, nothing written.
if "${J}" merge "${T}/part1.json" --json "${T}/bad.json" 2> "${T}/err"; then exit 1; fi
grep -q "shard(s) 2 of 2 missing" "${T}/err"
if "${J}" merge "${T}/part1.json" "${T}/part1.json" --json "${T}/bad.json" 2> "${T}/err"; then exit 1; fi
grep -q "given twice" "${T}/err"
test ! -e "${T}/bad.json"
# A bad --shard is a bad command line (exit 2).
set +e
"${J}" evaluate "${args[@]}" --shard 3/2 --json "${T}/x.json" 2> /dev/null
rc=$?
set -e
test "${rc}" -eq 2
# GNU parallel over three shards on this machine.
if command -v parallel > /dev/null; then
  JG_BIN="${J}" JG_JOBS=2 bash "${SRC}/scripts/cluster/parallel_campaign.sh" "${T}/gnu" 3 -- "${args[@]}" > /dev/null
  cmp "${T}/jobs1.json" "${T}/gnu/campaign.json"
  echo "GNU parallel: 3 shards merged, identical"
else
  echo "GNU parallel not installed: its part skipped"
fi
echo "scale: --jobs 1/2, 2 shards merged and GNU parallel give identical JSON"
