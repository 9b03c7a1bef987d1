#!/usr/bin/env bash
# ISO/TS 15066 outcomes (issue 17): the shipped body-region scenarios stay within their
# region's limits with the default reaction (stop), the clamped ones exceed them without a
# reaction; the built-in safety table covers every region, contact kind and reaction; a
# bad body region is refused naming the field.
# Usage: safety.sh JOINTGUARD SOURCE_DIR
set -euo pipefail
J="$1"
SRC="$2"
T="$(mktemp -d)"
trap 'rm -rf "${T}"' EXIT
for s in hand_clamp lower_arm_free chest_clamp abdomen_free; do
  reactions="stop"
  case "${s}" in *clamp) reactions="stop none" ;; esac
  for r in ${reactions}; do
    "${J}" evaluate --scenario "${SRC}/scenarios/iso_${s}.yaml" --calibration 60 --free-run 30 --no-hold --reaction "${r}" \
      --json "${T}/${s}_${r}.json" > /dev/null
  done
done
python3 - "${T}" <<'PY'
import json, sys, os
t = sys.argv[1]
for s in ["hand_clamp", "lower_arm_free", "chest_clamp", "abdomen_free"]:
    stop = json.load(open(os.path.join(t, s + "_stop.json")))["safety"]
    assert stop["within_limits"], (s, stop)
    assert stop["peak_quasi_static_n"] <= stop["limit_quasi_static_n"], (s, stop)
    assert stop["peak_transient_n"] <= 2 * stop["limit_quasi_static_n"], (s, stop)
    if s.endswith("clamp"):
        none = json.load(open(os.path.join(t, s + "_none.json")))["safety"]
        assert stop["peak_transient_n"] <= none["peak_transient_n"] + 1e-9, (s, stop, none)
        assert not none["within_limits"], (s, none)  # without a reaction the clamp exceeds its limit
        assert none["peak_quasi_static_n"] > 5 * stop["peak_quasi_static_n"] + 1, (s, none, stop)
    # Pressures on the default 1 cm^2 contact face, against the region's Table A.2 pressure.
    assert stop["contact_area_cm2"] == 1.0, stop
    assert abs(stop["peak_transient_pressure_n_per_cm2"] - stop["peak_transient_n"]) < 1e-9, stop
    assert stop["pressure_within_limits"] and stop["force_within_limits"], stop
    expected = {"hand_clamp": 190, "lower_arm_free": 180, "chest_clamp": 120, "abdomen_free": 140}[s]
    assert stop["limit_quasi_static_pressure_n_per_cm2"] == expected, stop
    assert stop["limit_transient_pressure_n_per_cm2"] == 2 * expected, stop
    print(s, "stop: transient %.1f N, quasi-static %.1f N" % (stop["peak_transient_n"], stop["peak_quasi_static_n"]))
PY
"${J}" evaluate --scenario safety --calibration 60 --no-hold --json "${T}/table.json" > /dev/null
python3 - "${T}/table.json" <<'PY'
import json, sys
cases = json.load(open(sys.argv[1]))["safety"]["cases"]
assert len(cases) == 12 * 2 * 5, len(cases)
assert {c["reaction"] for c in cases} == {"none", "stop", "zero_gravity", "retreat", "reflex"}
assert all(c["detection_delay_s"] is not None for c in cases), "every contact detected"
# #17.4: the estimated contact force beside the truth, for every detected contact.
assert all(c["force_estimate_peak_n"] is not None and c["force_estimate_peak_n"] > 0 for c in cases), "force estimated"
PY
# A bad body region: exit 1, the field named.
sed 's/body_region: hand/body_region: elbowx/' "${SRC}/scenarios/iso_hand_clamp.yaml" > "${T}/bad.yaml"
sed -i "s#model: ../models/ref3.yaml#model: ${SRC}/models/ref3.yaml#" "${T}/bad.yaml"
if "${J}" evaluate --scenario "${T}/bad.yaml" --json "${T}/bad.json" 2> "${T}/err"; then exit 1; fi
grep -q "body_region" "${T}/err"
test ! -e "${T}/bad.json"
echo "safety: body-region scenarios within their limits with stop, table complete"
