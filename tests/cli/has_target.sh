#!/usr/bin/env bash
# scripts/demo.sh's target detection (scripts/has_target.sh) against the real build folder:
# a target that exists is found, one that does not is not, and the cycle-benchmark ELF's
# target is found exactly when CMake defined it. Its first version piped the target list into
# `grep -q` under pipefail and never found a target (Broken pipe): the demo's report said
# "Not measured: cycle benchmark ELF not built".
# usage: has_target.sh SOURCE_DIR BUILD_DIR MCU_TARGET_EXISTS(0|1)
set -euo pipefail
SRC=$1 BUILD=$2 MCU=$3
DETECT="$SRC/scripts/has_target.sh"
fail() { echo "FAIL: $*" >&2; exit 1; }

bash "$DETECT" "$BUILD" jointguard || fail "the target 'jointguard' was not found in $BUILD"
if bash "$DETECT" "$BUILD" no_such_target_jg; then fail "a target that does not exist was found"; fi
if bash "$DETECT" "$BUILD" jg_mcu; then fail "a prefix of a target name was taken for the target"; fi
if [ "$MCU" = 1 ]; then
  bash "$DETECT" "$BUILD" jg_mcu_cortex_m4 || fail "jg_mcu_cortex_m4 exists in this build but was not found"
else
  if bash "$DETECT" "$BUILD" jg_mcu_cortex_m4; then fail "jg_mcu_cortex_m4 found but CMake did not define it"; fi
fi
set +e
bash "$DETECT" "$BUILD/no_such_folder" jointguard 2>/dev/null
rc=$?
set -e
[ "$rc" = 2 ] || fail "an unconfigured folder gave exit $rc, expected 2"
# demo.sh must use it, not a pipe into grep.
grep -q 'scripts/has_target.sh "$BUILD" jg_mcu_cortex_m4' "$SRC/scripts/demo.sh" || fail "demo.sh does not use scripts/has_target.sh"
if grep -Eq -- '--target help *\|' "$SRC/scripts/demo.sh"; then fail "demo.sh pipes the target list again"; fi
echo "has_target: ok"
