#!/usr/bin/env bash
# A campaign split over a bare set of machines with GNU parallel: each shard is one
# `jointguard evaluate --shard K/N` job, the parts are merged into the JSON of one run.
#
#   scripts/cluster/parallel_campaign.sh OUT_DIR SHARDS [-- EVALUATE_ARGS...]
#
# Machines: set JG_SSHLOGINS to GNU parallel's --sshlogin list (e.g. "2/node1,2/node2";
# every machine needs the same jointguard binary at JG_BIN and a shared OUT_DIR); unset,
# the shards run on this machine, JG_JOBS at a time (default: all cores). Each shard
# runs its own runs on one thread (--jobs 1): parallel spreads the shards.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OUT_DIR SHARDS [-- EVALUATE_ARGS...]" >&2
  exit 2
fi
out="$1"
shards="$2"
shift 2
if [ "${1:-}" = "--" ]; then shift; fi
bin="${JG_BIN:-$(cd "$(dirname "$0")/../.." && pwd)/build/host/jointguard}"
command -v parallel >/dev/null || { echo "GNU parallel is not installed (Debian: apt-get install parallel)" >&2; exit 1; }
mkdir -p "${out}"
where=()
if [ -n "${JG_SSHLOGINS:-}" ]; then
  where=(--sshlogin "${JG_SSHLOGINS}")
else
  where=(-j "${JG_JOBS:-0}")
fi
# --halt now,fail=1: one failed shard stops the campaign (its message is kept in the log).
seq 1 "${shards}" | parallel "${where[@]}" --halt now,fail=1 --joblog "${out}/parallel.log" \
  "\"${bin}\" evaluate $* --jobs 1 --shard {}/${shards} --json \"${out}/part{}.json\" > \"${out}/part{}.log\" 2>&1"
parts=()
for k in $(seq 1 "${shards}"); do parts+=("${out}/part${k}.json"); done
"${bin}" merge "${parts[@]}" --json "${out}/campaign.json"
