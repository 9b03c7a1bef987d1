#!/usr/bin/env python3
"""Writes the small synthetic recordings of this folder (deterministic; no real data).
Each is an odd case a real logger or a user can produce; tests/cli/run_odd_recordings.sh
runs every one through diagnose, identify, calibrate and replay.
Usage: python3 make_recordings.py   (from this folder). shoulder_first_0.2s.csv is the
README's shoulder recording cut to its first 0.2 s:
  jointguard simulate scenarios/paper_collision_shoulder.yaml --out /tmp/shoulder.csv
  awk -F, 'NR==1 || $1 <= 0.2' /tmp/shoulder.csv > shoulder_first_0.2s.csv"""
import math
import random

rng = random.Random(7)


def write(name, header, rows):
    with open(name, "w") as f:
        f.write(",".join(header) + "\n")
        for r in rows:
            f.write(",".join(("%.7g" % v) if isinstance(v, float) else str(v) for v in r) + "\n")


def header(n, torque="i"):
    return ["t"] + ["q%d" % j for j in range(1, n + 1)] + ["dq%d" % j for j in range(1, n + 1)] + \
        ["%s%d" % (torque, j) for j in range(1, n + 1)]


def row(t, q, dq, tau):
    return [float(t)] + [float(v) for v in q] + [float(v) for v in dq] + [float(v) for v in tau]


# Held arm (3 joints, 500 Hz, 1.2 s): encoder noise only, far less than 0.047 rad of motion.
rows = []
for k in range(600):
    q = [0.1 + rng.gauss(0, 2e-4), 0.5 + rng.gauss(0, 2e-4), -0.3 + rng.gauss(0, 2e-4)]
    dq = [rng.gauss(0, 1e-3) for _ in range(3)]
    i = [0.05 + rng.gauss(0, 0.01), 1.2 + rng.gauss(0, 0.01), 0.4 + rng.gauss(0, 0.01)]
    rows.append(row(k * 2e-3, q, dq, i))
write("held_arm.csv", header(3), rows)

# One joint moving (joint 2, a slow sine), the others held, 250 Hz, 3 s.
rows = []
for k in range(750):
    t = k * 4e-3
    w = 2 * math.pi * 0.5
    q = [0.1 + rng.gauss(0, 1e-4), 0.5 + 0.4 * math.sin(w * t), -0.3 + rng.gauss(0, 1e-4)]
    dq = [rng.gauss(0, 1e-3), 0.4 * w * math.cos(w * t), rng.gauss(0, 1e-3)]
    i = [0.05 + rng.gauss(0, 0.01), 1.2 * math.cos(q[1]) + 0.3 * math.copysign(1, dq[1]) + rng.gauss(0, 0.01),
         0.4 + rng.gauss(0, 0.01)]
    rows.append(row(t, q, dq, i))
write("one_joint_moving.csv", header(3), rows)

# Constant signals: every value the same in every row (a logger stuck, or a perfect rest).
write("constant.csv", header(3), [row(k * 1e-3, [0.1, 0.5, -0.3], [0, 0, 0], [0.1, 1.0, 0.4]) for k in range(300)])

# A single sample and two samples.
write("single_sample.csv", header(3), [row(0.0, [0.1, 0.5, -0.3], [0, 0, 0], [0.1, 1.0, 0.4])])
write("two_samples.csv", header(3), [row(0.0, [0.1, 0.5, -0.3], [0, 0, 0], [0.1, 1.0, 0.4]),
                                      row(0.001, [0.1, 0.5, -0.3], [0.01, 0, 0], [0.1, 1.0, 0.4])])

# A 7-joint arm with a joint torque sensor (tau_j), 125 Hz, 4 s, every joint on a slow sine.
rows = []
for k in range(500):
    t = k * 8e-3
    q, dq, tau = [], [], []
    for j in range(7):
        w = 2 * math.pi * (0.2 + 0.05 * j)
        q.append(0.3 * math.sin(w * t + j))
        dq.append(0.3 * w * math.cos(w * t + j))
        tau.append((5.0 - 0.6 * j) * math.sin(w * t + j + 0.3) + rng.gauss(0, 0.02))
    rows.append(row(t, q, dq, tau))
write("seven_joint_tau_j.csv", header(7, "tau_j"), rows)

# An irregular log (3 joints, nominally 200 Hz, 4 s): jittered stamps (3.5-6.5 ms), rows
# repeating the previous state (the logger read it twice), skipped samples, and one gap
# of 0.3 s that splits it in two.
rows = []
t = 0.0
k = 0
prev = None
while t < 4.0:
    w = 2 * math.pi * 0.4
    state = (0.3 * math.sin(w * t), 0.3 * w * math.cos(w * t))
    q = [0.1 + state[0], 0.5 + 0.5 * state[0], -0.3 - state[0]]
    dq = [state[1], 0.5 * state[1], -state[1]]
    i = [0.5 * math.copysign(1, dq[0]) + 0.2 * dq[0], 1.2 * math.cos(q[1]), 0.3 * math.copysign(1, dq[2])]
    r = row(t, q, dq, i)
    rows.append(r)
    if prev is not None and rng.random() < 0.05:  # a repeat: the previous state, a new stamp
        t += rng.uniform(0.0035, 0.0065)
        rows.append([float(t)] + r[1:])
    prev = r
    step = rng.uniform(0.0035, 0.0065)
    if rng.random() < 0.03:
        step += 0.005  # a skipped state
    if 2.0 <= t < 2.0 + step:
        step += 0.3  # the long gap
    t += step
    k += 1
write("irregular_gap.csv", header(3), rows)
