"""Scores replays of the real UR10e's held arm (static_pushes.csv) and its collision-free
motion (motion_free.csv) at the defaults (real_pipeline.sh, issue 31.2).

A push's events are those from its visible onset - 0.1 s to the README's end + 1.0 s, as in
ur10e_score.py (the onset: the first row from 0.5 s before the README's start at which some
joint's K·i has left its level of the second ending 0.5 s before the start by more than
max(4 sigma, 0.3 N·m) for 3 rows). Fails (exit 1) when a push has no event, when an event
falls outside every push, or when motion_free has any event.
Usage: ur10e_pushes.py <data dir> <static_pushes replay JSON> <motion_free replay JSON>
"""
import csv
import json
import statistics
import sys

data, static_json, free_json = sys.argv[1:4]
PUSHES = [(3.17, 5.64), (11.64, 15.87), (25.37, 30.94), (37.96, 43.26)]  # README, t - t0 [s]

k_i = next([float(v) for v in line.split("[")[1].split("]")[0].split(",")]
           for line in open(f"{data}/drive.yaml") if line.startswith("k_i:"))
rows = list(csv.DictReader(open(f"{data}/static_pushes.csv")))
t0 = float(rows[0]["t"])
t = [float(r["t"]) - t0 for r in rows]
tau = [[k_i[j] * float(r[f"i{j + 1}"]) for r in rows] for j in range(6)]


def onset(a, b):
    best = None
    for j in range(6):
        pre = [tau[j][i] for i, x in enumerate(t) if a - 1.5 <= x < a - 0.5]
        level, bar = statistics.mean(pre), max(4.0 * statistics.pstdev(pre), 0.3)
        for i, x in enumerate(t):
            if x < a - 0.5 or i + 3 > len(t):
                continue
            if x > b:
                break
            if all(abs(tau[j][i + q] - level) > bar for q in range(3)):
                best = x if best is None else min(best, x)
                break
    return best


static = json.load(open(static_json))["events"]
ev = [e["t"] - t0 for e in static]
claimed, ok, detected = set(), True, 0
print("static_pushes: push  README start  visible onset  first event  delay [ms]  events in it  by")
for n, (a, b) in enumerate(PUSHES, 1):
    on = onset(a, b)
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
