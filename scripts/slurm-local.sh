#!/bin/bash
# Runs deploy/slurm/ on a real Slurm cluster of one node (this machine) and
# checks every merged frame bitwise against a single-process render
# (docs/farm.md, "On a scheduler").
#
#   sudo [LUCENT=path/to/lucent] bash scripts/slurm-local.sh [TEST...]
#
# TEST (default: all four):
#   frame     one frame, 4 bands, array indices from 1 (not 0), ARGS that
#             replace the scripts' --threads and --checkpoint; then a
#             finished task requeued: skipped, its log appended
#   sequence  3 frames (shot.%04d.toml) x 2 parts in one array, one merge
#             per frame
#   timeout   one part under a 1-minute time limit that needs longer: the
#             task is warned, requeues itself, resumes and completes
#   cancel    scancel of a running part: its samples kept, the merge
#             cancelled; the same submission again resumes and completes
# Each submits through deploy/slurm/submit.sh, waits for the queue to empty,
# renders the same frames in one process and compares pixels bit for bit
# (idiff, zero thresholds) and PNGs byte for byte. Prints each test's wall
# time; exit 0 only if all pass.
#
# Needs root (starts munged, slurmctld and slurmd). Installs Debian 12's
# slurm-wlm (22.05) and munge with apt-get when missing, writes a minimal
# slurm.conf for one node named after this host into a private directory
# ($WORK, default /tmp/lucent-slurm; nothing under /etc/slurm), and stops
# the daemons it started on exit. Without LUCENT it builds the `quick`
# profile (the release arithmetic).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
WORK=${WORK:-/tmp/lucent-slurm}
tests=("$@")
[ ${#tests[@]} -gt 0 ] || tests=(frame sequence timeout cancel)
if [ "$(id -u)" != 0 ]; then
  echo "slurm-local.sh: needs root (starts munged, slurmctld, slurmd)" >&2
  exit 2
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge
fi
if [ -z "${LUCENT:-}" ]; then
  cargo build --profile quick --quiet
  LUCENT=$ROOT/target/quick/lucent
fi
[ -x "$LUCENT" ] || { echo "${0##*/}: no lucent binary at $LUCENT (build it, or set LUCENT)" >&2; exit 2; }
LUCENT=$(realpath "$LUCENT")
export LUCENT

rm -rf "$WORK"
mkdir -p "$WORK"/{state,spool}
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

# the node as slurmd sees it (CPUs, sockets, memory); finished jobs stay
# visible to scontrol for an hour (MinJobAge); the schedulers look at the
# queue every 5 s rather than 60 and 30 (a requeued task starts sooner)
NODE=$(slurmd -C | head -1)
cat >"$WORK/slurm.conf" <<CONF
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
SchedulerParameters=sched_interval=5,bf_interval=5
ReturnToService=2
MpiDefault=none
MinJobAge=3600
$NODE State=UNKNOWN
PartitionName=main Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$WORK/slurm.conf

stop() {
  local d p
  for d in slurmd slurmctld; do
    [ -f "$WORK/$d.pid" ] || continue
    p=$(cat "$WORK/$d.pid")
    kill "$p" 2>/dev/null || continue
    for _ in $(seq 30); do kill -0 "$p" 2>/dev/null || break; sleep 1; done
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

# Waits until the queue is empty (at most $1 seconds). Slurm holds a
# requeued job back for about two minutes (its begin time); with $2 = nudge
# such a job may start 3 s from now instead, to keep the test short. Not
# sooner: a job started within the second of its requeue is refused
# ("Job credential revoked") and fails.
drain() {
  local end=$((SECONDS + $1)) j r begin
  while [ -n "$(squeue -h -o %i)" ]; do
    if [ $SECONDS -ge $end ]; then
      squeue >&2
      echo "slurm: jobs still queued after $1 s; logs in $WORK" >&2
      exit 1
    fi
    if [ "${2:-}" = nudge ]; then
      while read -r j r begin; do
        [ "$r" = BeginTime ] && [ "$begin" != N/A ] &&
          [ $(($(date -d "$begin" +%s) - $(date +%s))) -gt 10 ] &&
          scontrol update JobId="$j" StartTime=now+3
      done < <(squeue -h -t PD -o '%i %r %S')
    fi
    sleep 2
  done
}

# Compares a merged frame with the single-process render of the same scene
# (render options in the remaining arguments; a scene named FRAME.single.exr
# is that render, made already): pixels bit for bit, the PNG
# byte for byte. Not the EXR bytes: the single render's header records its
# render time, which a merge cannot know.
check() {
  local frame=$1 scene=$2 single=${1%.exr}.single.exr
  shift 2
  [ -f "$frame" ] || { echo "slurm: no merged frame $frame (logs in $WORK)" >&2; exit 1; }
  [ "$scene" = "$single" ] || "$LUCENT" render "$scene" --quiet -o "$single" "$@"
  if idiff -q -fail 0 -warn 0 "$frame" "$single" >/dev/null &&
    cmp "${frame%.exr}.png" "${single%.exr}.png"; then
    echo "  $(basename "$frame"): pixels and PNG bitwise equal to one process"
  else
    echo "slurm: $frame DIFFERS from the single-process render" >&2
    exit 1
  fi
}

# cornell.toml at another resolution and spp
shot() {
  sed -e "s/^resolution = .*/resolution = [$2, $2]/" -e "s/^spp = .*/spp = $3/" \
    "$ROOT/scenes/cornell.toml" >"$1"
}

test_frame() {
  local d=$WORK/frame
  mkdir -p "$d/out"
  shot "$d/cornell.toml" 256 8
  (cd "$d" && SCENE=$d/cornell.toml OUT=$d/out PARTS=4 BASE=1 \
    ARGS="--threads 1 --checkpoint=30" "$ROOT/deploy/slurm/submit.sh")
  drain 600
  check "$d/out/frame.exr" "$d/cornell.toml"
  # a finished task run again (as a requeue after its end would) leaves its
  # part as it is, and its log keeps both runs
  cp "$d/out/part-0.exr" "$d/part-0.before"
  scontrol requeue "$(squeue -h -t all -o '%A %K' | awk '$2 == 1 {print $1}')"
  drain 600 nudge
  if ! grep -q 'exists: nothing to do' "$d"/lucent-part-*_1.log ||
    [ "$(grep -c ' task ' "$d"/lucent-part-*_1.log)" != 2 ] ||
    ! cmp "$d/out/part-0.exr" "$d/part-0.before"; then
    echo "slurm: a finished part was rendered again (log: $d/lucent-part-*_1.log)" >&2
    exit 1
  fi
  echo "  a finished task requeued: skipped, part unchanged, log appended"
}

test_sequence() {
  local d=$WORK/sequence f
  mkdir -p "$d/out"
  for f in 1 2 3; do
    shot "$d/shot.000$f.toml" 128 8
    sed -i "s/^look_from = .*/look_from = [0.$((f * 2)), 1.0, 3.8]/" "$d/shot.000$f.toml"
  done
  (cd "$d" && SCENE=$d/shot.%04d.toml FRAMES=1-3 OUT=$d/out PARTS=2 \
    "$ROOT/deploy/slurm/submit.sh")
  drain 600
  for f in 1 2 3; do check "$d/out/shot.000$f.exr" "$d/shot.000$f.toml"; done
}

# The spp at which a 256x256 cornell.toml needs about $2 s of one core on
# this machine, measured in directory $1 (at least 64).
spp_for() {
  local t0 t1 spp
  shot "$1/probe.toml" 256 8
  t0=$(date +%s%N)
  "$LUCENT" render "$1/probe.toml" --threads 1 --quiet -o "$1/probe.exr"
  t1=$(date +%s%N)
  spp=$(($2 * 8 * 1000000000 / (t1 - t0 + 1)))
  [ "$spp" -ge 64 ] && echo "$spp" || echo 64
}

# A 1-minute limit, stopped 30 s before it (LEAD): each run renders about
# 30 s. The render is sized to need about 60 s of one core on this machine
# (measured first), so it takes at least two runs; the single-process
# render runs on the other core meanwhile.
test_timeout() {
  local d=$WORK/timeout spp ref
  mkdir -p "$d/out"
  spp=$(spp_for "$d" 60)
  shot "$d/cornell.toml" 256 "$spp"
  echo "  256x256 at $spp spp"
  (cd "$d" && SCENE=$d/cornell.toml OUT=$d/out PARTS=1 LEAD=30 \
    "$ROOT/deploy/slurm/submit.sh" --time=1)
  "$LUCENT" render "$d/cornell.toml" --threads 1 --quiet -o "$d/out/frame.single.exr" &
  ref=$!
  drain 900 nudge
  wait "$ref"
  grep -q requeueing "$d"/lucent-part-*.log || {
    echo "slurm: the task was not requeued (log: $d/lucent-part-*.log)" >&2
    exit 1
  }
  echo "  runs: $(grep -c ' task ' "$d"/lucent-part-*.log) ($(grep -c requeueing "$d"/lucent-part-*.log) requeue(s))"
  check "$d/out/frame.exr" "$d/out/frame.single.exr"
}

# scancel of a running part (about 20 s of work) once it has run 3 s: lucent
# keeps its samples, the frame's merge is cancelled rather than left
# pending, and the same submission again resumes and completes the frame.
test_cancel() {
  local d=$WORK/cancel spp ref task
  mkdir -p "$d/out"
  spp=$(spp_for "$d" 20)
  shot "$d/cornell.toml" 256 "$spp"
  "$LUCENT" render "$d/cornell.toml" --threads 1 --quiet -o "$d/out/frame.single.exr" &
  ref=$!
  (cd "$d" && SCENE=$d/cornell.toml OUT=$d/out PARTS=1 "$ROOT/deploy/slurm/submit.sh")
  for _ in $(seq 60); do grep -qs '^/' "$d"/lucent-part-*.log && break; sleep 1; done
  sleep 3
  task=$(squeue -h -t R -n lucent-part -o %A)
  [ -n "$task" ] || { echo "slurm: the part was not running to be cancelled" >&2; exit 1; }
  scancel "$task"
  drain 120
  if [ -f "$d/out/frame.exr" ] || [ ! -f "$d/out/part-0.partial.exr" ]; then
    echo "slurm: after scancel: a frame, or no kept samples (log: $d/lucent-part-*.log)" >&2
    exit 1
  fi
  echo "  cancelled: $(grep -o 'samples 0\.\.[0-9]* of 0\.\.[0-9]* kept' "$d"/lucent-part-*.log), merge cancelled"
  (cd "$d" && SCENE=$d/cornell.toml OUT=$d/out PARTS=1 "$ROOT/deploy/slurm/submit.sh")
  drain 300
  grep -q -- '--resume' "$d"/lucent-part-*.log || { echo "slurm: the resubmitted part did not resume" >&2; exit 1; }
  wait "$ref"
  check "$d/out/frame.exr" "$d/out/frame.single.exr"
}

for t in "${tests[@]}"; do
  echo "slurm: $t"
  start=$SECONDS
  "test_$t"
  echo "slurm: $t passed in $((SECONDS - start)) s wall"
done
