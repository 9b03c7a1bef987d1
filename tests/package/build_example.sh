#!/usr/bin/env bash
# The firmware library as a drive maker takes it: install a cross build of the core
# (default build/cortex-m4), then build the example drive firmware (examples/stm32g4_drive,
# copied out of the source tree so that it can only reach the installed package) with
# find_package(jointguard), and check that neither image pulls in the heap, exceptions or
# unwinding. Usage: tests/package/build_example.sh [BUILD_DIR]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${1:-${root}/build/cortex-m4}"
work="$(mktemp -d)"
trap 'rm -rf "${work}"' EXIT
cmake --install "${build}" --prefix "${work}/prefix" >/dev/null
test -f "${work}/prefix/include/jointguard.h"
test -f "${work}/prefix/lib/cmake/jointguard/jointguardConfig.cmake"
cp -r "${root}/examples/stm32g4_drive" "${work}/src"
cmake -S "${work}/src" -B "${work}/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_TOOLCHAIN_FILE="${root}/toolchain/arm-none-eabi.cmake" -DCMAKE_PREFIX_PATH="${work}/prefix" >/dev/null
cmake --build "${work}/build" -j2
for elf in drive_cpp drive_c; do
  f="${work}/build/${elf}.elf"
  test -f "${f}"
  if arm-none-eabi-nm "${f}" | grep -E ' (malloc|free|_Znwj|_Znaj|_ZdlPv|_ZdaPv|__cxa_throw|__cxa_allocate_exception|_Unwind_[A-Za-z_]+)$'; then
    echo "example ${elf}: heap or exception symbols linked in" >&2
    exit 1
  fi
done
# Without the package the example refuses to configure (find_package REQUIRED).
if cmake -S "${work}/src" -B "${work}/wrong" -DCMAKE_PREFIX_PATH="${work}/nowhere" >/dev/null 2>&1; then
  echo "example configured without a jointguard package" >&2
  exit 1
fi
echo "example drive firmware built against the installed package: OK"
