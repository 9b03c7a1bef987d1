#!/usr/bin/env python3
"""Writes t_ms.csv: a 7-joint motion whose time stamps are in milliseconds (issue 29:
`identify t_ms.csv --model models/panda.yaml --rigid-body --torque-kind joint` read "21000
rows at 1 Hz" and wrote link 4 at 8.75 kg with exit 0). dq is in rad/s, so dq is 1000 times
the change of q over t. Deterministic. Usage: python3 make_t_ms.py (from this folder)."""
import math

N = 7
with open("t_ms.csv", "w") as f:
    f.write(",".join(["t"] + ["q%d" % j for j in range(1, N + 1)] + ["dq%d" % j for j in range(1, N + 1)] +
                     ["tau_m%d" % j for j in range(1, N + 1)]) + "\n")
    for k in range(300):
        t = 0.001 * k  # seconds; written in milliseconds below
        w = 2.0 * math.pi * 0.8
        q = [0.4 * math.sin(w * t + j) for j in range(N)]
        dq = [0.4 * w * math.cos(w * t + j) for j in range(N)]
        tau = [5.0 * math.sin(w * t + j) for j in range(N)]
        f.write(",".join(["%d" % k] + ["%.9g" % v for v in q + dq + tau]) + "\n")
