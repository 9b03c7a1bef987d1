#!/usr/bin/env bash
# The whole test suite, from a fresh Debian 12 machine: installs what is missing,
# configures, builds and tests
#   host      float firmware scalar: unit, simulation, MCU (qemu) and static-analysis tests
#   host-q    the same core with the Q16.16 firmware scalar
#   host-san  AddressSanitizer + UndefinedBehaviorSanitizer
#   fuzz      the readers' libFuzzer targets (clang, ASan + UBSan incl. float-cast-overflow
#             and integer), a short smoke each (docs/fuzzing.md; the long run: scripts/fuzz.sh)
#   cortex-m4 / cortex-m7 / cortex-m3 / cortex-m33 cross builds of the firmware (M4: the contract's preset)
#   package   the cortex-m4 build installed, the example drive firmware built against it
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
for preset in host host-q host-san fuzz; do
  echo "=== preset ${preset}"
  cmake --preset "${preset}" >/dev/null
  cmake --build --preset "${preset}"
  ctest --preset "${preset}"
done
for preset in cortex-m4 cortex-m7 cortex-m3 cortex-m33; do
  echo "=== preset ${preset}"
  cmake --preset "${preset}" >/dev/null
  cmake --build --preset "${preset}"
done
echo "=== package: install the cortex-m4 build, build the example drive firmware against it"
bash tests/package/build_example.sh build/cortex-m4
echo "jointguard: all test presets passed"
