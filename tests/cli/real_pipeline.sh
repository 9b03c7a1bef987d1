#!/usr/bin/env bash
# The pipeline closed on the real arms (issue 31.1), read from ../shared/data/real (skipped
# with a message when absent; never copied here): every recording where it makes sense goes
# identify -> calibrate -> replay at the defaults, and no step may refuse the file the
# previous one wrote (exit 0 each, in both firmware scalars):
#  - UR10e (vendor URDF + drive.yaml, ~100 Hz): identify on motion_free and on
#    motion_contacts (the two motions), calibrate on motion_free (the collision-free one),
#    replay motion_free, motion_contacts and static_pushes;
#  - Panda (models/panda.yaml, ~1 kHz, joint torque sensors): identify, calibrate and
#    replay on the excitation.
# Every bounded parameter carries its reason in the friction JSON. Prints the figures for
# docs/results.md (events per replay). At the defaults, with friction and thresholds from
# UR10e motion_free: all 4 pushes of static_pushes detected, no event outside them and none
# on motion_free, in both scalars (ur10e_pushes.py; the holding detector is on by default).
# Usage: real_pipeline.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$2"
DATA="$SRC/../shared/data/real"
U="$DATA/ur10e-static"
P="$DATA/panda-excitation/panda_excitation.csv"
if [ ! -f "$U/motion_free.csv" ] || [ ! -f "$U/ur10e.urdf" ] || [ ! -f "$P" ]; then
  echo "skipped: real recordings not found in $DATA"
  exit 77
fi
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
PY=/usr/bin/python3
fail=0
step() {  # step NAME COMMAND...: runs it, reports a refusal (any non-zero exit) with its message
  local name="$1"
  shift
  if ! "$@" > "$W/$name.txt" 2> "$W/$name.err"; then
    echo "REFUSED: $name: $(tail -1 "$W/$name.err")"
    fail=1
    return 1
  fi
}
events() { "$PY" -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["events"]))' "$1"; }
check_notes() {  # every bounded parameter says why; the file states the rate it fits
  "$PY" - "$1" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
assert d["firmware_rate_hz"] > 0, "friction file without its firmware rate"
for j in d["joints"]:
    for b in j["bounded"]:
        assert b["reason"] and b["parameter"] in ("sigma0", "sigma1", "sigma2", "tau_c", "tau_s", "w_s"), b
        print(f"  joint {j['joint']}: {b['parameter']} {b['fitted']:.3g} -> {b['written']:.3g}")
PYEOF
}
UM=(--model "$U/ur10e.urdf" --drive "$U/drive.yaml")
for id in motion_free motion_contacts; do
  step "identify_$id" "$J" identify "$U/$id.csv" "${UM[@]}" --json "$W/fr_$id.json" || continue
  echo "UR10e identify $id: bounded"
  check_notes "$W/fr_$id.json"
  th="$W/th_${id}.json"
  step "calibrate_${id}" "$J" calibrate "$U/motion_free.csv" "${UM[@]}" --friction "$W/fr_$id.json" --json "$th" || continue
  for scalar in float q; do
    for rec in motion_free motion_contacts static_pushes; do
      out="$W/replay_${id}_${rec}_$scalar.json"
      step "replay_${id}_${rec}_$scalar" "$J" replay "$U/$rec.csv" "${UM[@]}" --friction "$W/fr_$id.json" --threshold "$th" \
        --scalar "$scalar" --json "$out" || continue
      echo "UR10e friction from $id, replay $rec ($scalar): $(events "$out") event(s)"
    done
    # At the defaults (issue 31.2): friction and thresholds from motion_free alone, holding
    # derived from the recording: every push on the held arm detected, no event outside the
    # pushes, none on motion_free.
    if [ "$id" = motion_free ] && ! "$PY" "$SRC/tests/cli/ur10e_pushes.py" "$U" "$W/replay_${id}_static_pushes_$scalar.json" \
      "$W/replay_${id}_motion_free_$scalar.json"; then
      echo "FAILED: UR10e at the defaults ($scalar): a push missed or a false alarm (above)"
      fail=1
    fi
  done
done
PM=(--model "$SRC/models/panda.yaml" --torque-kind joint)
if step identify_panda "$J" identify "$P" "${PM[@]}" --json "$W/fr_panda.json"; then
  echo "Panda identify: bounded"
  check_notes "$W/fr_panda.json"
  if step calibrate_panda "$J" calibrate "$P" "${PM[@]}" --friction "$W/fr_panda.json" --json "$W/th_panda.json"; then
    for scalar in float q; do
      if step "replay_panda_$scalar" "$J" replay "$P" "${PM[@]}" --friction "$W/fr_panda.json" --threshold "$W/th_panda.json" \
        --scalar "$scalar" --json "$W/replay_panda_$scalar.json"; then
        echo "Panda replay excitation ($scalar): $(events "$W/replay_panda_$scalar.json") event(s)"
      fi
    done
  fi
fi
exit "$fail"
