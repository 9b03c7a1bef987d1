#!/usr/bin/python3
"""Compares two `jointguard evaluate --json` outputs run by run (for example float against
Q16.16 on the same scenario and seed): detections, the cycles between them, isolated links.

Usage: /usr/bin/python3 scripts/compare_evaluations.py A.json B.json
Exit 1 when the runs differ in name or count, or a file cannot be read.
"""
import json
import sys


def load(path):
    try:
        with open(path) as f:
            j = json.load(f)
        return j["runs"], float(j["summary"]["rate"])
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"{path}: not an evaluate JSON ({e})")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    (a, rate_a), (b, rate_b) = load(sys.argv[1]), load(sys.argv[2])
    if [r["name"] for r in a] != [r["name"] for r in b]:
        sys.exit("the two files hold different runs")
    if rate_a != rate_b:
        sys.exit(f"different rates: {rate_a} and {rate_b} Hz")
    detection_differs, isolation_differs, worst_cycles = [], [], 0
    for x, y in zip(a, b):
        if (x["t_detected"] is None) != (y["t_detected"] is None):
            detection_differs.append(x["name"])
            continue
        if x["t_detected"] is not None:
            worst_cycles = max(worst_cycles, round(abs(x["t_detected"] - y["t_detected"]) * rate_a))
        if x["link_isolated"] != y["link_isolated"]:
            isolation_differs.append(f'{x["name"]} (link {x["link_true"]}: {x["link_isolated"]} / {y["link_isolated"]})')
    print(f"{len(a)} runs at {rate_a:g} Hz; detected in one file only: {len(detection_differs)}; "
          f"largest detection difference: {worst_cycles} cycles; isolated differently: {len(isolation_differs)}")
    for name in detection_differs:
        print(f"  detected in one file only: {name}")
    for line in isolation_differs:
        print(f"  isolated differently: {line}")


if __name__ == "__main__":
    main()
