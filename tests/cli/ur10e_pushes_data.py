"""The real UR10e's held-arm recording (static_pushes.csv) as the scoring scripts read it:
the README's push times, K·i per joint, and the visible onset of a push.

Visible onset: the pre-push level of K·i per joint is its mean over the second that ends
0.5 s before the README's start, its noise the standard deviation there; the onset is the
first row from 0.5 s before the README's start at which some joint's K·i has left its level
by more than max(4 sigma, 0.3 N·m) for 3 rows in a row.
"""
import csv
import statistics

PUSHES = [(3.17, 5.64), (11.64, 15.87), (25.37, 30.94), (37.96, 43.26)]  # README, t - t0 [s]


def k_i(data):
    for line in open(f"{data}/drive.yaml"):
        if line.startswith("k_i:"):
            return [float(v) for v in line.split("[")[1].split("]")[0].split(",")]
    raise SystemExit(f"{data}/drive.yaml: no k_i")


def static_pushes(data):
    """(t0, t - t0, K·i per joint) of static_pushes.csv."""
    k = k_i(data)
    rows = list(csv.DictReader(open(f"{data}/static_pushes.csv")))
    t0 = float(rows[0]["t"])
    t = [float(r["t"]) - t0 for r in rows]
    tau = [[k[j] * float(r[f"i{j + 1}"]) for r in rows] for j in range(6)]
    return t0, t, tau


def pre_push_level(t, tau_j, a):
    """K·i samples of one joint over the second ending 0.5 s before the README's start `a`."""
    return [tau_j[i] for i, x in enumerate(t) if a - 1.5 <= x < a - 0.5]


def visible_onset(t, tau, a, b):
    """The push (a, b)'s visible onset [s after t0], or None."""
    best = None
    for j in range(len(tau)):
        pre = pre_push_level(t, tau[j], a)
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
