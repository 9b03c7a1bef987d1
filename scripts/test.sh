#!/usr/bin/env bash
# The whole test suite, from a fresh Debian 12 machine: installs what is missing,
# configures, builds and tests
#   host      float firmware scalar: unit, simulation, MCU (qemu) and static-analysis tests
#   host-q    the same core with the Q16.16 firmware scalar
#   host-san  AddressSanitizer + UndefinedBehaviorSanitizer
#   fuzz      the readers' libFuzzer targets (clang, ASan + UBSan incl. float-cast-overflow
#             and integer), a short smoke each (docs/fuzzing.md; the long run: scripts/fuzz.sh)
#   cortex-m4 / cortex-m7 cross builds of the firmware (the contract's preset commands)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/deps.sh
for preset in host host-q host-san fuzz; do
  echo "=== preset ${preset}"
  cmake --preset "${preset}" >/dev/null
  cmake --build --preset "${preset}"
  ctest --preset "${preset}"
done
for preset in cortex-m4 cortex-m7; do
  echo "=== preset ${preset}"
  cmake --preset "${preset}" >/dev/null
  cmake --build --preset "${preset}"
done
echo "jointguard: all test presets passed"
