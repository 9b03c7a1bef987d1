#!/usr/bin/env bash
# The concealed-effect test set over threads (issue 18): the same drawn cases with --jobs 1
# and --jobs 2 must print the same lines, in case order.
# Usage: diagnosis_testset_jobs.sh JG_DIAGNOSIS_TESTSET
set -euo pipefail
B="$1"
T="$(mktemp -d)"
trap 'rm -rf "${T}"' EXIT
"${B}" --jobs 1 4 11 > "${T}/jobs1.txt"
"${B}" 4 11 --jobs 2 > "${T}/jobs2.txt"
test "$(grep -c 'joint [0-9]' "${T}/jobs1.txt")" -eq 4 || { echo "expected 4 case lines"; cat "${T}/jobs1.txt"; exit 1; }
cmp "${T}/jobs1.txt" "${T}/jobs2.txt" || { diff "${T}/jobs1.txt" "${T}/jobs2.txt"; exit 1; }
"${B}" --jobs -1 4 11 > /dev/null 2>&1 && { echo "--jobs -1 accepted"; exit 1; }
# The second generator (issue 30 item 6): the same over threads; a generator it lacks refused.
"${B}" --generator second --jobs 1 4 11 > "${T}/second1.txt"
"${B}" --generator second --jobs 2 4 11 > "${T}/second2.txt"
test "$(grep -c 'joint [0-9]' "${T}/second1.txt")" -eq 4 || { echo "expected 4 second-generator case lines"; cat "${T}/second1.txt"; exit 1; }
cmp "${T}/second1.txt" "${T}/second2.txt" || { diff "${T}/second1.txt" "${T}/second2.txt"; exit 1; }
cmp -s "${T}/jobs1.txt" "${T}/second1.txt" && { echo "the second generator printed the first one's cases"; exit 1; }
rc=0; "${B}" --generator third 4 11 > /dev/null 2>&1 || rc=$?
test "${rc}" -eq 2 || { echo "--generator third: exit ${rc}, expected 2"; exit 1; }
echo "jg_diagnosis_testset: --jobs 1 and --jobs 2 identical (both generators)"
