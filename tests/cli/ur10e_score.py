"""Scores the UR10e replays of real_ur10e_detection.sh against the data's README times.

Visible onset of a push: ur10e_pushes_data.py. A push's events are those
from its onset - 0.1 s (one 100 Hz step of resampling) to its README end + 1.0 s (the release and the friction it leaves
are part of the push); any other event is a false alarm.
Usage: ur10e_score.py <data dir> <work dir>
"""
import csv
import json
import statistics
import sys

from ur10e_pushes_data import PUSHES, pre_push_level, static_pushes, visible_onset

data, work = sys.argv[1], sys.argv[2]
EPISODES = [(3.4, 4.2), (9.4, 10.0), (16.5, 16.93)]                        # motion_contacts
STOP_FREE = 5.06                                                            # motion_free's stop


def events(name):
    return [e["t"] for e in json.load(open(f"{work}/{name}.json"))["events"]]


t0, t, tau = static_pushes(data)
ok = True
for run in ("static", "static_still"):
    ev = [e - t0 for e in events(run)]
    claimed = set()
    print(f"{run}: push  README start  visible onset  first event  delay [ms]  events in the push")
    for n, (a, b) in enumerate(PUSHES, 1):
        onset = visible_onset(t, tau, a, b)
        mine = [e for e in ev if onset - 0.1 <= e <= b + 1.0]
        claimed.update(mine)
        if not mine:
            print(f"{n:4d}  {a:12.2f}  {onset:13.3f}  missed")
            ok = False
            continue
        print(f"{n:4d}  {a:12.2f}  {onset:13.3f}  {mine[0]:11.3f}  {1e3 * (mine[0] - onset):10.0f}  {len(mine)}")
    false = [e for e in ev if e not in claimed]
    print(f"{run}: false alarms outside them: {len(false)} {false}")
    ok = ok and not false

# The contact estimate of each push's first event (replay's "contact"): a link, a point and
# a force with spreads, and a followed peak force that can make the push's torques at all: the
# largest change of K.i over the push, divided by the arm's reach (1.3 m, the longest lever
# any contact has), is a lower bound on the force [N]; 1,000 N is far above a hand's push.
static = json.load(open(f"{work}/static.json"))["events"]
print("static: push  contact link  along [m]  force at decision [N]  peak [N]  lower bound [N]")
for n, (a, b) in enumerate(PUSHES, 1):
    first = next((e for e in static if a - 0.5 <= e["t"] - t0 <= b + 1.0), None)
    if first is None:
        continue  # missed: reported above
    c = first.get("contact")
    pre = [pre_push_level(t, tau[j], a) for j in range(6)]
    change = max(abs(tau[j][i] - statistics.mean(pre[j])) for j in range(6) for i, x in enumerate(t) if a <= x <= b)
    bound = change / 1.3
    if c is None:
        print(f"{n:4d}  no contact estimate")
        ok = False
        continue
    print(f"{n:4d}  {c['link']:12d}  {c['along_m']:5.2f} +- {c['along_sigma_m']:.2f}  {c['force_n']:8.1f} +- {c['force_sigma_n']:5.1f}"
          f"  {c['peak_force_n']:8.1f}  {bound:8.1f}")
    ok = ok and 1 <= c["link"] <= 6 and c["force_sigma_n"] > 0 and bound <= c["peak_force_n"] <= 1000.0

t0f = float(next(csv.DictReader(open(f"{data}/motion_free.csv")))["t"])
free = {v: [round(e - t0f, 3) for e in events(f"motion_free_{v}")] for v in ("band", "widen", "gate")}
print(f"motion_free (calibrated on its first 5 s), alarms: band alone {free['band']}, "
      f"widening law {free['widen']}, stop gate {free['gate']}")
ok = ok and not free["gate"] and any(abs(e - STOP_FREE) < 0.1 for e in free["band"])

t0c = float(next(csv.DictReader(open(f"{data}/motion_contacts.csv")))["t"])
for variant in ("band", "widen", "gate"):
    evc = [e - t0c for e in events(f"motion_contacts_{variant}")]
    hits = [[e for e in evc if a - 0.5 <= e <= b + 0.5] for a, b in EPISODES]
    outside = [e for e in evc if not any(a - 0.5 <= e <= b + 0.5 for a, b in EPISODES)]
    print(f"motion_contacts, {variant}: events {[round(e, 3) for e in evc]}; per episode "
          f"{[len(h) for h in hits]}; outside the episodes {outside}")
    ok = ok and not outside and hits[0] and hits[2]
if not ok:
    raise SystemExit("UR10e detection: FAILED")
print("UR10e detection: ok")
