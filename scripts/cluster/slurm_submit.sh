#!/usr/bin/env bash
# Submits a sharded campaign to Slurm: an array job of SHARDS tasks, then the merge once
# every task has succeeded (afterok). Prints the merge job's id.
#   scripts/cluster/slurm_submit.sh OUT_DIR SHARDS [-- EVALUATE_ARGS...]
# JG_BIN: the jointguard binary on the compute nodes (default: this tree's build/host).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OUT_DIR SHARDS [-- EVALUATE_ARGS...]" >&2
  exit 2
fi
out="$(mkdir -p "$1" && cd "$1" && pwd)"
shards="$2"
shift 2
if [ "${1:-}" = "--" ]; then shift; fi
here="$(cd "$(dirname "$0")" && pwd)"
bin="${JG_BIN:-${here}/../../build/host/jointguard}"
array=$(sbatch --parsable --array="1-${shards}" --chdir="${out}" \
  --export="ALL,JG_OUT=${out},JG_BIN=${bin},JG_ARGS=$*" "${here}/slurm_campaign.sbatch")
parts=""
for k in $(seq 1 "${shards}"); do parts="${parts} ${out}/part${k}.json"; done
sbatch --parsable --dependency="afterok:${array}" --chdir="${out}" --job-name=jointguard-merge \
  --output="${out}/merge.log" --wrap="\"${bin}\" merge ${parts} --json \"${out}/campaign.json\""
