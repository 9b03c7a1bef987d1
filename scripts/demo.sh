#!/usr/bin/env bash
# The main job, from a fresh Debian 12 machine: installs what is missing, builds the
# host preset's CLI and the Cortex-M4F cross build (so that the report carries the
# firmware's measured cost per cycle) and runs `jointguard demo`.
# usage: scripts/demo.sh [OUT_DIR]   (default out/)
# JG_DEMO_BUILD=DIR uses that configured build folder instead of configuring the host
# preset's build/host: the test suite runs this script on its own build folder
# (tests/cli/render_report.sh), so what it checks is what a fresh machine runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
BUILD=${JG_DEMO_BUILD:-build/host}
if [ -z "${JG_DEMO_BUILD:-}" ]; then
  cmake --preset host >/dev/null
fi
cmake --build "$BUILD" --parallel 2 --target jointguard   # the host build preset's 2 jobs
# The cycle-bench ELF the report measures under qemu (a target only when the arm toolchain
# and qemu were found; scripts/deps.sh installs them).
# scripts/has_target.sh reads the whole target list first: a `| grep -q` here failed under
# pipefail (Broken pipe) and the report said "Not measured: cycle benchmark ELF not built".
if bash scripts/has_target.sh "$BUILD" jg_mcu_cortex_m4; then
  cmake --build "$BUILD" --parallel 2 --target jg_mcu_cortex_m4
else
  echo "demo.sh: no jg_mcu_cortex_m4 target (arm toolchain or qemu missing): the report's firmware cost is not measured" >&2
fi
"$BUILD/jointguard" demo --out "${1:-out}"
