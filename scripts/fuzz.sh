#!/usr/bin/env bash
# The long fuzz run of every reader (tests/fuzz): builds the preset `fuzz` (clang, libFuzzer,
# ASan + UBSan with float-cast-overflow and integer checks) and runs each reader's target
# one after the other, niced, from a copy of its seed corpus plus the regression inputs.
#   scripts/fuzz.sh [SECONDS] [RUNS] [READER...]
# SECONDS per reader (default 600), RUNS: stop a reader after this many executions
# (default 10000000, whichever comes first). READERS default to all of them.
# Prints per reader: executions, seconds, result; a finding's input lands in
# build/fuzz/long/<reader>/ (crash-*, leak-*, timeout-*, oom-*) and the script exits 1.
# Environment: JG_FUZZ_OUT, the output folder (default build/fuzz/long; two chains of
# readers run side by side each need their own), JG_FUZZ_TIMEOUT, the seconds an input may
# take before it counts as a hang (default 10; a niced run beside other work is starved of
# the CPU for whole seconds, and an input of 0.1 s then "takes" more than 10).
# JG_FUZZ_FORK=N (N >= 2): one run of libFuzzer's fork mode, N worker processes on N cores
# that share one corpus; the parent counts the executions of all of them and stops the run at
# RUNS. Timeouts and out-of-memory count as findings, as in the default mode (fork mode
# ignores them unless told otherwise). Without it: one process.
# JG_FUZZ_BUILD: the fuzz preset's build folder (default build/fuzz; configured with
# `cmake --preset fuzz -B DIR` and built here when given).
# ASAN_OPTIONS defaults to malloc_context_size=2: ASan records 2 frames, not 30, for each
# allocation and free (the stack depot and unwinding were a fifth of the drive fuzzer's
# time). Errors are detected as before and their inputs saved; replaying one through the
# same binary without the option gives the full stacks. Not 0 or 1: LeakSanitizer then
# reports no leak at all (checked with a 40-byte leak, clang 14).
set -euo pipefail
export ASAN_OPTIONS="${ASAN_OPTIONS:-malloc_context_size=2}"
cd "$(dirname "$0")/.."
SECONDS_PER_READER="${1:-600}"
RUNS="${2:-10000000}"
shift $(( $# > 2 ? 2 : $# ))
READERS=("$@")
[ ${#READERS[@]} -gt 0 ] || READERS=(recording robot_yaml urdf scenario param_json dbc candump drive merge_parts)
ROOT="$PWD"
BUILD="${JG_FUZZ_BUILD:-$ROOT/build/fuzz}"
cmake --preset fuzz -B "$BUILD" > /dev/null
cmake --build "$BUILD" -j2 --target jg_fuzz_all
# The targets write each input to a file: in memory when /dev/shm is there.
if [ -z "${JG_FUZZ_TMP:-}" ] && [ -w /dev/shm ]; then export JG_FUZZ_TMP=/dev/shm; fi
OUT="${JG_FUZZ_OUT:-$ROOT/build/fuzz/long}"
TIMEOUT="${JG_FUZZ_TIMEOUT:-10}"
FORK="${JG_FUZZ_FORK:-1}"
if [ "$FORK" -ge 2 ]; then
  MODE=(-fork="$FORK" -ignore_timeouts=0 -ignore_ooms=0 -ignore_crashes=0)
else
  MODE=(-jobs=1 -workers=1)
fi
mkdir -p "$OUT"
status=0
printf '%-12s %12s %8s %s\n' reader executions seconds result | tee "$OUT/summary.txt"
for r in "${READERS[@]}"; do
  W="$OUT/$r"
  rm -rf "$W" && mkdir -p "$W/corpus"
  cp tests/fuzz/corpus/"$r"/* "$W/corpus/"
  start=$(date +%s)
  set +e
  # -jobs=1: one worker process (its output in $W/fuzz-0.log), restarted never (fork mode:
  # driver.log has the parent's progress); -timeout:
  # an input taking $TIMEOUT s (10 by default) is a finding (a reader must refuse, not hang); -max_len: inputs up
  # to 8 kB (the seeds are smaller; the 23 kB DBC and 40 kB regression only start them).
  (cd "$W" && nice -n 10 "$BUILD/tests/fuzz/fuzz_$r" corpus "$ROOT/tests/fuzz/regressions/$r" \
     "${MODE[@]}" -max_total_time="$SECONDS_PER_READER" -runs="$RUNS" -timeout="$TIMEOUT" -max_len=8192 -seed=1 \
     -print_final_stats=1 -artifact_prefix="$W/" > driver.log 2>&1)
  rc=$?
  set -e
  secs=$(( $(date +%s) - start ))
  if [ "$FORK" -ge 2 ]; then  # the parent's last progress line, "#<executions>: cov: ..."
    runs=$(grep -ao "#[0-9]*: cov" "$W"/driver.log | grep -o "[0-9]*" | tail -1 || true)
  else
    runs=$(grep -ho "stat::number_of_executed_units: *[0-9]*" "$W"/fuzz-0.log | grep -o "[0-9]*$" | tail -1 || true)
  fi
  if compgen -G "$W/crash-*" > /dev/null || compgen -G "$W/leak-*" > /dev/null || compgen -G "$W/timeout-*" > /dev/null ||
     compgen -G "$W/oom-*" > /dev/null; then rc=${rc/#0/1}; fi
  if [ "$rc" = 0 ]; then result=ok; else result="FINDING (exit $rc, see $W/fuzz-0.log or driver.log)"; status=1; fi
  printf '%-12s %12s %8s %s\n' "$r" "${runs:-?}" "$secs" "$result" | tee -a "$OUT/summary.txt"
done
exit $status
