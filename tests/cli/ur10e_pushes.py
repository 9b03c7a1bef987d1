"""Scores replays of the real UR10e's held arm (static_pushes.csv) and its collision-free
motion (motion_free.csv) at the defaults (real_pipeline.sh, issue 31.2).

A push's events are those from its visible onset - 0.1 s to the README's end + 1.0 s, as in
ur10e_score.py (the visible onset: ur10e_pushes_data.py). Fails (exit 1) when a push has no event, when an event
falls outside every push, or when motion_free has any event.
Usage: ur10e_pushes.py <data dir> <static_pushes replay JSON> <motion_free replay JSON>
"""
import json
import sys

from ur10e_pushes_data import PUSHES, static_pushes, visible_onset

data, static_json, free_json = sys.argv[1:4]
t0, t, tau = static_pushes(data)


static = json.load(open(static_json))["events"]
ev = [e["t"] - t0 for e in static]
claimed, ok, detected = set(), True, 0
print("static_pushes: push  README start  visible onset  first event  delay [ms]  events in it  by")
for n, (a, b) in enumerate(PUSHES, 1):
    on = visible_onset(t, tau, a, b)
    mine = [i for i, e in enumerate(ev) if on - 0.1 <= e <= b + 1.0]
    claimed.update(mine)
    if not mine:
        print(f"{n:4d}  {a:12.2f}  {on:13.3f}  missed")
        ok = False
        continue
    detected += 1
    first = static[mine[0]]
    by = "holding detector" if first["by_hold"] else "band"
    print(f"{n:4d}  {a:12.2f}  {on:13.3f}  {ev[mine[0]]:11.3f}  {1e3 * (ev[mine[0]] - on):10.0f}  {len(mine):12d}  {by}, "
          f"joints {first['joints_over']}")
outside = [round(ev[i], 3) for i in range(len(ev)) if i not in claimed]
free = json.load(open(free_json))["events"]
print(f"static_pushes: {detected} of {len(PUSHES)} pushes detected, {len(ev)} events, outside the pushes: {len(outside)} {outside}")
print(f"motion_free: {len(free)} events {[e['t'] for e in free]}")
if not ok or outside or free:
    raise SystemExit("UR10e at the defaults: FAILED")
print("UR10e at the defaults: ok")
