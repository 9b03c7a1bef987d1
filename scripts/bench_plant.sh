#!/usr/bin/env bash
# Plant speed, two binaries side by side in one run: `simulate` of the reference arm's
# collision-free scenario (3 joints, 1 kHz control, 2 kHz RK4 plant) for SECONDS of
# simulated time, OLD and NEW alternately ROUNDS times; the best user-CPU time of each
# (least disturbed by other load) gives the real-time factor and the ratio. The CSV
# recordings of the two are compared (largest difference per column): a faster plant must
# give the same results up to rounding.
# Usage: scripts/bench_plant.sh OLD_BIN NEW_BIN [SECONDS=600] [ROUNDS=3]
set -euo pipefail
old=${1:?old binary}
new=${2:?new binary}
seconds=${3:-600}
rounds=${4:-3}
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
best_old=1e9
best_new=1e9
for ((r = 1; r <= rounds; ++r)); do
  for which in old new; do
    bin=$old
    [[ $which == new ]] && bin=$new
    /usr/bin/time -f "%U" -o "$tmp/t" "$bin" simulate "$here/scenarios/free_motion.yaml" --duration "$seconds" \
      --out "$tmp/$which.csv" > /dev/null
    t=$(cat "$tmp/t")
    echo "round $r $which: $t s user CPU"
    if [[ $which == old ]]; then best_old=$(/usr/bin/python3 -c "print(min($best_old, $t))"); else best_new=$(/usr/bin/python3 -c "print(min($best_new, $t))"); fi
  done
done
/usr/bin/python3 - "$tmp/old.csv" "$tmp/new.csv" "$seconds" "$best_old" "$best_new" <<'PY'
import csv, sys
s, to, tn = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
print(f"old: {s / to:.0f}x real time ({to:.2f} s), new: {s / tn:.0f}x real time ({tn:.2f} s): {to / tn:.2f}x faster "
      "(whole process: plant, sensors, controller and the CSV written)")
with open(sys.argv[1]) as fa, open(sys.argv[2]) as fb:
    ra, rb = csv.reader(fa), csv.reader(fb)
    names = next(ra)
    next(rb)
    diff, top = [0.0] * len(names), [0.0] * len(names)
    for x, y in zip(ra, rb):
        for i, (u, v) in enumerate(zip(x, y)):
            diff[i] = max(diff[i], abs(float(u) - float(v)))
            top[i] = max(top[i], abs(float(u)))
for n, d, t in zip(names, diff, top):
    if d > 0: print(f"  {n}: max |old - new| = {d:.3g} (max |old| {t:.3g})")
print("the two recordings are identical" if max(diff) == 0 else "largest difference: %.3g" % max(diff))
PY
