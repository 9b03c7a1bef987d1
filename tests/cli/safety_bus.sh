#!/usr/bin/env bash
# Reactions on the joint drives (issue 17): the same body-region contacts with the reaction
# computed in the evaluation loop (in-process) and run by the drives' firmware on the
# simulated CAN FD bus (the master commands it, the drives send their torques back), in
# float and Q16.16. Tolerance: transient peak within 10 % + 5 N (the drives start one
# control cycle after the detection: the master's command goes out with the next sync),
# quasi-static peak within 5 N, the same verdict; and every reaction on the bus removes
# most of the clamp's quasi-static force (so drives that never reacted fail).
# Usage: safety_bus.sh JOINTGUARD
set -euo pipefail
J="$1"
T="$(mktemp -d)"
trap 'rm -rf "${T}"' EXIT
for s in float q; do
  "${J}" evaluate --scenario safety --region hand --region chest --kind clamp --compare-bus --scalar "${s}" \
    --calibration 60 --no-hold --json "${T}/${s}.json" > /dev/null
done
/usr/bin/python3 - "${T}" <<'PY'
import json, os, sys
t = sys.argv[1]
for scalar in ["float", "q"]:
    cases = json.load(open(os.path.join(t, scalar + ".json")))["safety"]["cases"]
    assert len(cases) == 2 * 5, len(cases)
    none = {c["region"]: c["bus"] for c in cases if c["reaction"] == "none"}
    for c in cases:
        b = c["bus"]
        d_tr = abs(b["peak_transient_n"] - c["peak_transient_n"])
        d_qs = abs(b["peak_quasi_static_n"] - c["peak_quasi_static_n"])
        assert d_tr <= 0.10 * c["peak_transient_n"] + 5.0, (scalar, c)
        assert d_qs <= 5.0, (scalar, c)
        assert b["within_limits"] == c["within_limits"], (scalar, c)
        if c["reaction"] != "none":
            assert b["peak_quasi_static_n"] < 0.2 * none[c["region"]]["peak_quasi_static_n"], (scalar, c)
        print("%-5s %-6s %-13s in-process %6.1f / %5.1f N, bus %6.1f / %5.1f N" % (
            scalar, c["region"], c["reaction"], c["peak_transient_n"], c["peak_quasi_static_n"],
            b["peak_transient_n"], b["peak_quasi_static_n"]))
PY
echo "safety_bus: the drives' reactions on the bus match the in-process loop"
