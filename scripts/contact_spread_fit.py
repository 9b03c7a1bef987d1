#!/usr/bin/env python3
"""Calibrates the contact estimate's torque spread on one campaign (issue 31 item 3).

Reads `jointguard evaluate --scenario campaign --json CAMPAIGN.json` (run with the window
model's current noise scale and lag uncertainty, given here) and, from every estimate's
torques beside the true torques at the same cycle, finds the noise scale c and the lag
uncertainty u for which the torque errors are what the spread says: the share of
|error| / sigma above 2 closest to a Gaussian's 4.6 %, and above 1 closest to its 31.7 %
(both counted on every joint of every estimate). Each joint's sigma^2 is
(c sigma_noise)^2 + (u lag)^2, split from the JSON's `torque_sigma` and `torque_sigma_lag`.
Prints the pair; a scale so fitted must be judged on another seed (held out).

Usage: contact_spread_fit.py CAMPAIGN.json [--scale C] [--lag U]
"""
import argparse
import json
import math


def rows_of(path, scale, lag):
    rows = []
    for r in json.load(open(path))["runs"]:
        c = r.get("contact_estimate")
        if not c or not c.get("torque_sigma_lag"):
            continue
        for x, xt, s, sl in zip(c["torque"], c["torque_true"], c["torque_sigma"], c["torque_sigma_lag"]):
            noise = math.sqrt(max(s * s - sl * sl, 0.0)) / scale
            rows.append((abs(x - xt), noise, sl / lag if lag > 0 else 0.0))
    return rows


def shares(rows, c, u):
    z = [e / math.sqrt((c * n) ** 2 + (u * l) ** 2) for e, n, l in rows]
    return sum(v > 2 for v in z) / len(z), sum(v > 1 for v in z) / len(z)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("campaign")
    ap.add_argument("--scale", type=float, default=1.0, help="the noise scale the campaign ran with")
    ap.add_argument("--lag", type=float, default=1.0, help="the lag uncertainty the campaign ran with")
    a = ap.parse_args()
    rows = rows_of(a.campaign, a.scale, a.lag)
    if not rows:
        raise SystemExit("no estimates with torque_sigma_lag in " + a.campaign)
    print(f"{len(rows)} joint torques; as run (c {a.scale}, u {a.lag}): above 2 sigma {shares(rows, a.scale, a.lag)[0]:.3f}, "
          f"above 1 sigma {shares(rows, a.scale, a.lag)[1]:.3f}")
    best = None
    for i in range(5, 101):
        for k in range(0, 31):
            c, u = i / 100.0, k / 10.0
            p2, p1 = shares(rows, c, u)
            cost = ((p2 - 0.0455) / 0.0455) ** 2 + ((p1 - 0.3173) / 0.3173) ** 2
            if best is None or cost < best[0]:
                best = (cost, c, u, p2, p1)
    _, c, u, p2, p1 = best
    print(f"fitted: noise scale {c:.2f}, lag uncertainty {u:.1f} (above 2 sigma {p2:.3f}, above 1 sigma {p1:.3f})")


if __name__ == "__main__":
    main()
