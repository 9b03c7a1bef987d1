#!/usr/bin/env bash
# Isolation after the stop (issue 15 item 2): the link is decided over the detection cycle
# and the next one, the latter on the estimate with the motor torque aligned to its momentum
# difference (host_sim/eval/aligned_estimate.hpp), so the stop's own torque step is not read
# as a contact; a joint at standstill takes part by its change, not its level. On a
# 100-collision campaign (short calibrations, about 20 s here) the decision must name the
# link in at least 65 of the 76 isolable (67 measured; the former rule, `--isolation-aligned 0
# --isolation-standstill-level`, 61) and at least 4 more than the detection cycle alone
# (`link_first_cycle`, 62); the ceiling at decision time is a subset of the ceiling and its
# counts match the runs.
# Usage: isolation.sh JOINTGUARD SOURCE_DIR
set -euo pipefail
J="$1"
T="$(mktemp -d)"
trap 'rm -rf "${T}"' EXIT
"${J}" evaluate --scenario campaign --count 100 --free-run 10 --calibration 600 --hold-calibration 60 --jobs 2 \
  --json "${T}/iso.json" > "${T}/iso.log"
grep -q "isolable at decision time" "${T}/iso.log"
/usr/bin/python3 - "${T}/iso.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
runs, s = d["runs"], d["summary"]
iso = [r for r in runs if r["isolable"]]
named = sum(r["link_isolated"] == r["link_true"] for r in iso)
first = sum(r["link_first_cycle"] == r["link_true"] for r in iso)
print(f"isolated of isolable {named}/{len(iso)} (detection cycle alone {first}/{len(iso)})")
assert s["isolation_aligned_s"] == 0.001 and s["isolation_standstill_change"] is True
assert s["isolable"] == len(iso) and s["isolated_of_isolable"] == named
assert named >= 65, f"isolation {named}/{len(iso)} below the floor 65"
assert named >= first + 4, f"the aligned cycle adds {named - first} (at least 4 expected)"
at = [r for r in runs if r["isolable_at_decision"]]
assert all(r["isolable"] for r in at), "isolable at decision time must be a subset of isolable"
assert s["isolable_at_decision"] == len(at)
assert s["isolated_of_isolable_at_decision"] == sum(r["link_isolated"] == r["link_true"] for r in at)
assert abs(s["isolation_ceiling_at_decision"] - len(at) / len(runs)) < 1e-12
PY
