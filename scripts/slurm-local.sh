#!/bin/bash
# Renders a frame on a real Slurm cluster of one node (this machine) and
# checks that the merged frame is bitwise the single-process render
# (issue 16; docs/farm.md).
#
#   sudo bash scripts/slurm-local.sh [SCENE] [N] [SPP]
#
# Needs root (it starts munged, slurmctld and slurmd). Installs Debian 12's
# slurm-wlm (22.05) and munge with apt-get when missing, writes a minimal
# slurm.conf for a single node named after this host into a private
# directory ($WORK, default /tmp/lucent-slurm; nothing under /etc/slurm),
# starts the daemons, submits deploy/slurm/render-array.sbatch as an array
# of N tasks (default 4, bands --tile i/N) and deploy/slurm/merge.sbatch
# depending on it, waits, renders the same frame in one process and
# compares the pixels bit for bit and the PNGs byte for byte. Stops the
# daemons it started on exit. Prints the wall time of the cluster run.
# Exit 0 only if equal.
#
# Run in CI only when LUCENT_SLURM_TEST=1 (scripts/test.sh): it needs root
# and starts system daemons.
set -euo pipefail
cd "$(dirname "$0")/.."
SCENE=${1:-scenes/cornell.toml}
N=${2:-4}
SPP=${3:-8}
WORK=${WORK:-/tmp/lucent-slurm}
if [ "$(id -u)" != 0 ]; then
  echo "slurm-local.sh: needs root (starts munged, slurmctld, slurmd)" >&2
  exit 2
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge
fi
cargo build --release --quiet
LUCENT=$PWD/target/release/lucent

rm -rf "$WORK"
mkdir -p "$WORK"/{state,spool,out}
chmod 755 "$WORK"
HOST=$(hostname -s)

# munge: a key if there is none, its daemon if none runs
if [ ! -s /etc/munge/munge.key ]; then
  mungekey --create --keyfile=/etc/munge/munge.key 2>/dev/null \
    || dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
  chown munge:munge /etc/munge/munge.key
  chmod 400 /etc/munge/munge.key
fi
started_munge=
if ! munge -n >/dev/null 2>&1; then
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge
  runuser -u munge -- /usr/sbin/munged
  started_munge=1
fi
munge -n | unmunge >/dev/null

# the node as slurmd sees it (CPUs, sockets, memory)
NODE=$(slurmd -C | head -1)
cat > "$WORK/slurm.conf" <<CONF
ClusterName=lucent
SlurmctldHost=$HOST
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
ReturnToService=2
MpiDefault=none
$NODE State=UNKNOWN
PartitionName=main Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$WORK/slurm.conf

stop() {
  for d in slurmd slurmctld; do
    [ -f "$WORK/$d.pid" ] && kill "$(cat "$WORK/$d.pid")" 2>/dev/null || true
  done
  if [ -n "$started_munge" ] && [ -f /run/munge/munged.pid ]; then
    kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
  fi
}
trap stop EXIT
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  state=$(sinfo -h -n "$HOST" -o %T 2>/dev/null || true)
  [ "$state" = idle ] && break
  sleep 1
done
[ "$state" = idle ] || { echo "node not idle: '$state'; see $WORK/*.log" >&2; exit 1; }

start=$(date +%s.%N)
cd "$WORK"
env_list="ALL,LUCENT=$LUCENT,SCENE=$OLDPWD/$SCENE,OUT=$WORK/out,SPP=$SPP"
array=$(sbatch --parsable --array=0-$((N - 1)) --export="$env_list" \
  "$OLDPWD/deploy/slurm/render-array.sbatch")
sbatch --parsable --wait --dependency=afterok:"$array" --export="$env_list" \
  "$OLDPWD/deploy/slurm/merge.sbatch" >/dev/null
end=$(date +%s.%N)
cd "$OLDPWD"

"$LUCENT" render "$SCENE" --spp "$SPP" --quiet -o "$WORK/single.exr"
wall=$(echo "$end - $start" | bc)
# The pixels bit for bit (idiff with zero thresholds fails on any
# difference) and the PNG byte for byte. Not the EXR bytes: the single
# render's header records its render time, which a merge cannot know.
if idiff -q -fail 0 -warn 0 "$WORK/out/frame.exr" "$WORK/single.exr" >/dev/null &&
  cmp "$WORK/out/frame.png" "$WORK/single.png"; then
  echo "slurm: $N array tasks + merge in ${wall} s wall; merged pixels and PNG bitwise equal to the single-process render"
else
  echo "slurm: merged frame DIFFERS from the single-process render" >&2
  exit 1
fi
