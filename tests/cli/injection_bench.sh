#!/usr/bin/env bash
# Known causes injected into the real recordings (issue 30 item 5), the small version of
# scripts/injection_bench.py (the full run and its table: docs/results.md). Skipped with a
# message when ../shared/data/real is absent; the recordings are never copied.
#  - Panda (0.3 and 1.5 kg at the flange + 2 zero-size cases): 1.5 kg named within 20 % (0.3 kg
#    is below what the full run names), no payload claim off by more than 20 %,
#    no claim on a zero-size case beyond the untouched recording's;
#  - UR10e motion_free (16 payloads, 0.5-12 kg, + 2 zero-size): the figures of the last
#    measured run as a floor (named >= 10, payload claims off by more than 20 % <= 2), no
#    claim on a zero-size case beyond the untouched recording's; the per-joint vocabulary
#    (--vocabulary): at most the one measured size beyond the range the diagnosis accepts
#    claimed, and the named count of the last measured run as a floor (36/98, docs/results.md);
#  - the same on the UR10e against the file the untouched recording's own diagnosis wrote
#    (--baseline: its links, friction and findings, as a user diagnoses a change on an arm
#    diagnosed before): the measured figures as floors (payloads 15/16, vocabulary 92/98),
#    nothing claimed on a zero-size case, and no more sizes beyond the accepted range claimed
#    than measured (1 of 15 since the nineteenth session, 2 before: a delay refined beyond
#    50 ms is not claimed; docs/results.md), and none of those sizes with other effects claimed
#    on its joint in its place (0 of 15 since the nineteenth session; 1 since the seventeenth: a
#    size beyond the range that explains more than what imitates it is reported as unexplained;
#    before, 11 of 15 got an inertia error or friction changes claimed instead); against the
#    robot file alone at most the measured 4. The named cases' sizes within 20 % of the injected
#    ones: at least the measured 78 (own file; 75 before the rows a recording was resampled from
#    were used) and 22 (file alone; 18 before).
# Usage: injection_bench.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
DATA="$SRC/../shared/data/real"
if [ ! -d "$DATA/panda-excitation" ] || [ ! -d "$DATA/ur10e-static" ]; then
  echo "skipped: real recordings not found in $DATA"
  exit 77
fi
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
PY=/usr/bin/python3
"$PY" scripts/injection_bench.py "$J" "$DATA" panda --cases 2 --json "$W/panda.json" > /dev/null
"$PY" scripts/injection_bench.py "$J" "$DATA" ur10e --vocabulary --json "$W/ur10e.json" > /dev/null
"$PY" scripts/injection_bench.py "$J" "$DATA" ur10e --vocabulary --baseline --json "$W/ur10e_baseline.json" > /dev/null
"$PY" - "$W/panda.json" "$W/ur10e.json" "$W/ur10e_baseline.json" <<'PYEOF'
import json, sys
p, u, b = (json.load(open(f))["summary"] for f in sys.argv[1:4])
print("panda:", p)
print("ur10e:", u)
print("ur10e against its own diagnosed file:", b)
assert b["named_within_20pct"] >= 15 and b["joint_effects_named"] >= 92, b  # measured 15/16, 92/98 (93 before the delay rule)
assert len(b["implausible_claimed"]) <= 1, b  # measured 1 of 15 (2 before the nineteenth session)
assert len(b["implausible_claimed_instead"]) == 0, b  # measured 0 of 15 (1 before the nineteenth session, 11 before the seventeenth)
assert len(u["implausible_claimed_instead"]) <= 4, u  # measured 4 of 15 (6 before)
assert b["zero_size_cases"] == 2 and b["zero_size_with_extra_claims"] == 0, b
# Sizes of the named cases within 20 % of the injected ones: the measured figures as floors
# (nineteenth session: 78/92 against its own file, 22/36 against the robot file alone).
def within(summary):
    return int(summary["named_size_within_20pct"].split("/")[0])
assert within(b) >= 78, b
assert within(u) >= 22, u
assert p["named_within_20pct"] >= 1 and p["wrong_claims"] == 0, p  # 0.3 kg (below the floor) and 1.5 kg
assert u["named_within_20pct"] >= 10 and u["wrong_claims"] <= 2, u  # measured 10/16 (docs/results.md)
# Beyond the range: not claimed, but for one measured: a 71 ms delay on joint 3 read as 23 ms
# beside a gear elasticity, against the robot file alone (7.7x the noise stays unexplained there).
assert u["implausible_cases"] >= 1 and len(u["implausible_claimed"]) <= 1, u
assert u["joint_effects_named"] >= 36, u  # measured 36/98 (38 before the nineteenth session's rows)
for s in (p, u):
    assert s["zero_size_cases"] == 2 and s["zero_size_with_extra_claims"] == 0, s
PYEOF
echo "injection bench: ok"
