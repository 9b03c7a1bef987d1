#!/usr/bin/python3
"""The most any contact estimate from the joint torques can reach on a campaign (issue 15).

Reads the JSON of `jointguard evaluate --scenario campaign ... --json FILE` and prints, for
the force magnitude within 20 % and the point within 5 cm along the link, an upper bound for
any estimator that sees only the joint torques:

- link-3 contacts are counted as right whenever the estimate at the true point is (or, more
  generously still, all of them with --link3-all);
- link-2 contacts of the reference arm: the waist's and the shoulder's axes meet at link 2's
  origin, so the torques are s J(1)^T F in every posture: they fix the moment, not the point
  s along the link nor the force apart from it. Every estimator then picks a point s' and
  states the force |F(s_true)| s_true / s'. The bound gives it the true link and the force
  the torques give at the true point (`force_given_true_point`, noise included), and lets it
  pick s' as a function of the moment's size, fitted to the campaign's own draw (quantile
  bins of the moment; fitted on half of the runs and counted on the other half, both ways;
  the best number of bins reported). That is more than an estimator can know (it is tuned to
  the test draw), so the figure is an upper bound, up to the point's small radial offset on
  a surface contact.

Usage: scripts/contact_ceiling.py CAMPAIGN.json [--truth observed|instant] [--link3-all]
Standard library only.
"""
import argparse
import bisect
import json
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign_json")
    ap.add_argument("--truth", choices=["observed", "instant"], default="observed",
                    help="the true force compared with: as the observer sees it (default) or at the estimate's cycle")
    ap.add_argument("--link3-all", action="store_true", help="count every link-3 contact as right")
    a = ap.parse_args()
    try:
        with open(a.campaign_json, encoding="utf-8") as f:
            doc = json.load(f)
        runs = [r for r in doc["runs"] if r.get("t_detected") is not None and "contact_estimate" in r]
    except (OSError, ValueError, KeyError, TypeError) as e:
        sys.exit(f"{a.campaign_json}: not a campaign JSON of jointguard evaluate ({e})")
    truth_key = "force_true_observed" if a.truth == "observed" else "force_true_at_estimate"

    def truth(r):
        return r["contact_estimate"][truth_key]

    def within(f, t):
        return abs(f - t) <= 0.2 * t

    by_link = {}
    for r in runs:
        by_link.setdefault(r["link_true"], []).append(r)
    if set(by_link) - {2, 3} or 2 not in by_link:
        sys.exit(f"{a.campaign_json}: expected contacts on links 2 and 3 of the reference arm, got links {sorted(by_link)}")
    n = len(runs)
    right_now = sum(within(r["contact_estimate"]["force"], truth(r)) for r in runs)
    point_now = sum(abs(r["contact_estimate"]["along_link"] - r["contact_estimate"]["along_link_true"]) <= 0.05 and
                    r["contact_estimate"]["link"] == r["link_true"] for r in runs)
    l3 = by_link.get(3, [])
    l3_force = len(l3) if a.link3_all else sum(within(r["contact_estimate"]["force_given_true_point"], truth(r)) for r in l3)
    l3_point = len(l3)  # the true point given: right by construction

    # Link 2: (moment size, true s, force at the true point, truth) per run.
    l2 = [(r["contact_estimate"]["force_given_true_point"] * r["contact_estimate"]["along_link_true"],
           r["contact_estimate"]["along_link_true"], truth(r)) for r in by_link[2]]
    grid = [0.02 + 0.0025 * k for k in range(400)]

    def force_hits(rows, s):
        return sum(within(m / s, t) for m, _, t in rows)

    def point_hits(rows, s):
        return sum(abs(s - s_true) <= 0.05 for _, s_true, _ in rows)

    def cross_validated(hits, nbins):
        total = 0
        for part in (0, 1):
            train = [v for i, v in enumerate(l2) if i % 2 == part]
            test = [v for i, v in enumerate(l2) if i % 2 != part]
            moments = sorted(v[0] for v in train)
            edges = [moments[len(moments) * k // nbins] for k in range(1, nbins)]
            bins = [[] for _ in range(nbins)]
            for v in train:
                bins[bisect.bisect(edges, v[0])].append(v)
            chosen = [max(grid, key=lambda s, b=b: hits(b, s)) for b in bins]
            total += sum(hits([v], chosen[bisect.bisect(edges, v[0])]) for v in test)
        return total

    l2_force = max(cross_validated(force_hits, k) for k in (1, 2, 4, 8, 16))
    l2_point = max(cross_validated(point_hits, k) for k in (1, 2, 4, 8, 16))
    print(f"{a.campaign_json}: {n} detections with a contact estimate ({len(by_link[2])} on link 2, {len(l3)} on link 3); "
          f"truth: the force {a.truth}")
    print(f"force within 20 %: the estimate {right_now}/{n} ({100.0 * right_now / n:.1f} %); "
          f"bound: link 3 {l3_force}/{len(l3)}, link 2 {l2_force}/{len(l2)}, "
          f"all {l3_force + l2_force}/{n} ({100.0 * (l3_force + l2_force) / n:.1f} %)")
    print(f"point within 5 cm along the link: the estimate {point_now}/{n} ({100.0 * point_now / n:.1f} %); "
          f"bound: link 3 {l3_point}/{len(l3)}, link 2 {l2_point}/{len(l2)}, "
          f"all {l3_point + l2_point}/{n} ({100.0 * (l3_point + l2_point) / n:.1f} %)")


if __name__ == "__main__":
    main()
