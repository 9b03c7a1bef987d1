#!/usr/bin/env bash
# The contact estimate in replay's events (eval/replay_contact.hpp): the README workflow on
# the paper's shoulder collision (60 N pushed on link 2 at 0.25 m along it, rising in 30 ms).
# The one event must carry a contact on link 2 whose followed peak is within 25 % of 60 N
# and whose point lies within 0.1 m of 0.25 m, with the two force components the link's
# torques determine and spreads > 0. Usage: replay_contact.sh <jointguard> <source dir>
set -euo pipefail
J="$1"
SRC="$(cd "$2" && pwd)"
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$SRC"
"$J" simulate scenarios/paper_excitation.yaml --out "$W/excitation.csv" > /dev/null
"$J" simulate scenarios/free_motion.yaml --out "$W/free.csv" > /dev/null
"$J" simulate scenarios/paper_collision_shoulder.yaml --out "$W/shoulder.csv" > /dev/null
"$J" identify "$W/excitation.csv" --model models/ref3.yaml --gain 150 --json "$W/friction.json" > /dev/null
"$J" calibrate "$W/free.csv" --model models/ref3.yaml --friction "$W/friction.json" --json "$W/threshold.json" > /dev/null
"$J" replay "$W/shoulder.csv" --model models/ref3.yaml --friction "$W/friction.json" --threshold "$W/threshold.json" \
  --json "$W/events.json" | tee "$W/replay.txt"
/usr/bin/python3 - "$W/events.json" <<'PY'
import json, sys
events = json.load(open(sys.argv[1]))["events"]
assert len(events) == 1, events
c = events[0].get("contact")
assert c is not None, "no contact estimate in the event"
print(f"contact: link {c['link']}, {c['along_m']:.3f} +- {c['along_sigma_m']:.3f} m, "
      f"{c['force_n']:.1f} +- {c['force_sigma_n']:.1f} N at {c['t']:.3f} s, peak {c['peak_force_n']:.1f} N")
assert c["link"] == 2, c
assert abs(c["peak_force_n"] - 60.0) <= 0.25 * 60.0, c
assert abs(c["along_m"] - 0.25) <= 0.1, c
assert c["determined_components"] == 2, c
assert c["force_sigma_n"] > 0 and c["along_sigma_m"] > 0, c
assert abs(c["t"] - events[0]["t"] - 0.02) < 1e-6, c  # decided 20 ms after the detection
assert len(c["point_base_m"]) == 3 and len(c["force_base_n"]) == 3, c
PY
