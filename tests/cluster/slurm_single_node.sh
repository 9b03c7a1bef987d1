#!/usr/bin/env bash
# A sharded campaign through Slurm on a single-node cluster started by this test
# (munged, slurmctld and slurmd as root, a private configuration and state folder), with
# scripts/cluster/slurm_submit.sh: the array job's parts merged by the dependent job must
# equal the unsharded command's JSON byte for byte. Skips (77) with the reason when the
# machine cannot run a cluster (not root, Slurm or munge missing).
# Usage: slurm_single_node.sh JOINTGUARD SOURCE_DIR
set -euo pipefail
J="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
SRC="$2"
skip() { echo "SKIP: $*"; exit 77; }
[ "$(id -u)" -eq 0 ] || skip "starting slurmd and munged needs root"
for c in munged slurmctld slurmd sbatch squeue scontrol; do
  command -v "${c}" > /dev/null || skip "${c} not installed (Debian: slurm-wlm, munge)"
done
T="$(mktemp -d /tmp/jg-slurm.XXXXXX)"
chmod 755 "${T}"
host="$(hostname -s)"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "${p}" 2> /dev/null || true; done
  sleep 1
  rm -rf "${T}"
}
trap cleanup EXIT
mkdir -p "${T}/munge" "${T}/state" "${T}/spool" "${T}/out" "${T}/run"
# munge: a key of our own, its socket in our folder (no system service touched).
dd if=/dev/urandom of="${T}/munge/munge.key" bs=1 count=1024 status=none
chmod 600 "${T}/munge/munge.key"
munged --force --key-file="${T}/munge/munge.key" --socket="${T}/munge/munge.socket" \
  --pid-file="${T}/munge/munged.pid" --log-file="${T}/munge/munged.log" --seed-file="${T}/munge/seed" ||
  skip "munged did not start: $(tail -3 "${T}/munge/munged.log" 2> /dev/null)"
pids+=("$(cat "${T}/munge/munged.pid")")
cpus="$(nproc)"
cat > "${T}/slurm.conf" <<CONF
ClusterName=jgtest
SlurmctldHost=${host}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=${T}/munge/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
StateSaveLocation=${T}/state
SlurmdSpoolDir=${T}/spool
SlurmctldPidFile=${T}/run/slurmctld.pid
SlurmdPidFile=${T}/run/slurmd.pid
SlurmctldLogFile=${T}/run/slurmctld.log
SlurmdLogFile=${T}/run/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
NodeName=${host} CPUs=${cpus} State=UNKNOWN
PartitionName=jg Nodes=${host} Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="${T}/slurm.conf"
slurmctld -f "${SLURM_CONF}" || skip "slurmctld did not start: $(tail -3 "${T}/run/slurmctld.log" 2> /dev/null)"
sleep 1
pids+=("$(cat "${T}/run/slurmctld.pid")")
slurmd -f "${SLURM_CONF}" || skip "slurmd did not start: $(tail -3 "${T}/run/slurmd.log" 2> /dev/null)"
sleep 1
pids+=("$(cat "${T}/run/slurmd.pid")")
for _ in $(seq 1 30); do
  if sinfo -h -o "%t" 2> /dev/null | grep -qE "idle|mix"; then break; fi
  sleep 1
done
sinfo -h -o "%t" | grep -qE "idle|mix" || skip "the node never became idle: $(sinfo 2>&1 | tail -2)"

args=(--scenario campaign --count 5 --free-run 700 --calibration 20 --no-hold)
"${J}" evaluate "${args[@]}" --jobs 1 --json "${T}/single.json" > /dev/null
merge_job=$(JG_BIN="${J}" bash "${SRC}/scripts/cluster/slurm_submit.sh" "${T}/out" 3 -- "${args[@]}")
for _ in $(seq 1 600); do
  if ! squeue -h -j "${merge_job}" 2> /dev/null | grep -q .; then break; fi
  sleep 1
done
state="$(scontrol show job "${merge_job}" 2> /dev/null | grep -o 'JobState=[A-Z_]*' || true)"
if [ ! -f "${T}/out/campaign.json" ]; then
  echo "merge job ${merge_job} (${state}) wrote no campaign.json" >&2
  tail -5 "${T}"/out/*.log >&2 || true
  exit 1
fi
cmp "${T}/single.json" "${T}/out/campaign.json"
echo "slurm: 3 array tasks on a single-node cluster, merged by a dependent job: identical JSON (${state})"
