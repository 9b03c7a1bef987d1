#!/usr/bin/env bash
# Identification speed: one paper-sized GA run (200 x 300 over 1251 samples) against
# SciPy's vectorised differential_evolution on the same data, bounds and budget, in one
# run on this machine (compare the ratio; absolute times depend on the machine's load).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! /usr/bin/python3 -c "import scipy" 2>/dev/null; then
  apt-get install -y -qq python3-scipy >/dev/null
fi
cmake --preset host >/dev/null
cmake --build --preset host --target jg_bench_identify >/dev/null
tmp=$(mktemp -d)
./build/host/tests/bench/jg_bench_identify --data "$tmp/data.csv" --runs 10 | tee "$tmp/ga.json"
/usr/bin/python3 scripts/bench_scipy_de.py "$tmp/data.csv" | tee "$tmp/scipy.json"
/usr/bin/python3 - "$tmp/ga.json" "$tmp/scipy.json" <<'PY'
import json, sys
ga = json.load(open(sys.argv[1])); sp = json.load(open(sys.argv[2]))
print(f"time ratio SciPy DE / jointguard GA (one run each): {sp['scipy_seconds'] / ga['ga_one_run_seconds']:.1f}x")
print(f"final objective: GA {ga['ga_one_run_objective']:.5g}, SciPy DE {sp['scipy_objective']:.5g} (noise variance 0.09)")
PY
rm -rf "$tmp"
