#!/usr/bin/python3
"""A recording's every column resampled onto a uniform grid by linear interpolation on its time
stamps (t0 + k * STEP up to its last row), as `jointguard` regularizes it: a copy whose rows are
the grid, to tell what resampling does to an effect (docs/history.md, nineteenth session).

Usage: resample_uniform.py IN.csv OUT.csv STEP_S
Only the Python standard library (the CI machine's /usr/bin/python3)."""
import csv
import sys


def main():
    if len(sys.argv) != 4:
        raise SystemExit(__doc__)
    src, dst, step = sys.argv[1], sys.argv[2], float(sys.argv[3])
    with open(src, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header, data = rows[0], rows[1:]
    if "t" not in header:
        raise SystemExit(f"{src}: no column 't'")
    ti = header.index("t")
    try:
        values = [[float(x) for x in r] for r in data]
    except ValueError as e:
        raise SystemExit(f"{src}: a field that is not a number ({e})")
    t = [v[ti] for v in values]
    if len(t) < 2 or any(b <= a for a, b in zip(t, t[1:])):
        raise SystemExit(f"{src}: field 't' must increase row to row")
    n = int((t[-1] - t[0]) / step + 1e-6) + 1
    with open(dst, "w") as out:
        out.write(",".join(header) + "\n")
        j = 0
        for k in range(n):
            tk = t[0] + k * step
            while j + 2 < len(t) and t[j + 1] <= tk:
                j += 1
            a = min(max((tk - t[j]) / (t[j + 1] - t[j]), 0.0), 1.0)
            row = [values[j][c] + a * (values[j + 1][c] - values[j][c]) for c in range(len(header))]
            row[ti] = tk
            out.write(",".join("%.9g" % v for v in row) + "\n")


if __name__ == "__main__":
    main()
