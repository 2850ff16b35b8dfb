#!/usr/bin/env bash
# cluster.sh: the end-to-end test of scale-out, run by `make test-cluster` (and so by
# `make test`). Every result is compared with cmp to a whole run on this machine:
#   1. GNU parallel: a 12-point sweep as 4 `ppbench sweep --shard I/4` on this machine, merged;
#   2. a real single-node Slurm cluster (Debian's slurm-wlm and munge), started here without
#      systemd (munged, slurmctld and slurmd in the foreground of this script, slurm.conf and
#      the munge key under the build directory), stopped at the end, also on failure (trap):
#      a. the same sweep as a 4-task job array plus its merge job (`ppbench slurm --submit`);
#      b. an experiment's Monte Carlo as a 4-task array plus mc-merge, one task killed while
#         running (scancel), the same command run again: it submits that shard alone.
# Slurm needs root (slurmd starts job steps as their user): without root the Slurm part is
# SKIPPED, said on stdout; PPB_REQUIRE_CLUSTER=1 (set by .ci/run) makes a skip a failure.
# Every command is bounded by timeout; the whole takes about two minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
ppbench=$(realpath "${PPBENCH:-./ppbench}")
build=$(realpath -m "${BUILD_DIR:-build}")
root=$build/cluster
port=${PPB_SLURM_PORT:-16817}
t0=$(date +%s)
say() { echo "cluster: $* ($(($(date +%s) - t0))s)"; }
rm -rf "$root"
mkdir -p "$root"

# The sweep: configs/sweep_example.ini's 12 points (g x albedo x theta) at a tiny budget.
sweep_cfg=configs/sweep_example.ini
sweep_set=(--set experiment.methods=mc,mp --set mc.photons=2e4 --set tube.segments_top=16
           --set tube.segments_side=6)
# The Monte Carlo: each shard runs a few seconds, so that one can be killed while running. At
# 1e7 photons (2.5e6 a shard) the 3x faster kernel finished a shard within a second:
# a fresh-clone CI run (2026-12-02) cancelled task 4 after it had written its tallies. 4e8: a
# shard is 1e8 photons, several seconds on 2 cores shared by 2 tasks (the whole run about 12 s).
mc_cfg=configs/uniform_g0_normal.ini
mc_set=(--set experiment.methods=mc --set mc.photons=4e8)

fails=0
same() { # same A B: cmp, said either way
  if cmp "$1" "$2"; then echo "cmp: identical: $1 $2"; else echo "cmp: DIFFERENT: $1 $2"; fails=1; fi
}
# Every file of a whole run but its timings and provenance (wall times, paths) and the PDFs
# (cairo stamps each with its creation time; the PNGs of the same figures are compared);
# config.ini without its [output] dir line, the one setting that names where a run went.
same_outputs() {
  local f n=0
  while IFS= read -r f; do
    if [ "$f" = ./config.ini ]; then
      same <(grep -v '^dir = ' "$1/$f") <(grep -v '^dir = ' "$2/$f")
    else
      same "$1/$f" "$2/$f"
    fi
    n=$((n + 1))
  done < <(cd "$1" && find . -type f ! -name timings.csv ! -name provenance.txt ! -name '*.pdf' |
    sort)
  [ "$n" -gt 0 ] || { echo "cmp: no files in $1"; fails=1; }
}

say "whole sweep on this machine"
timeout 300 "$ppbench" sweep --quiet "${sweep_set[@]}" --out "$root/whole_sweep" "$sweep_cfg"
say "whole Monte Carlo on this machine"
timeout 300 "$ppbench" run --quiet "${mc_set[@]}" --out "$root/whole_mc" "$mc_cfg"

# 1. GNU parallel, the README's example (--sshlogin host1,host2 spreads it over hosts).
say "GNU parallel: 4 shards"
timeout 300 parallel -j 2 "$ppbench" sweep --quiet "${sweep_set[@]}" --shard {}/4 \
  --out "$root/parallel/shard{}" "$sweep_cfg" ::: 1 2 3 4
timeout 60 "$ppbench" merge --out "$root/parallel/merged" "$root"/parallel/shard{1,2,3,4}
same "$root/parallel/merged/sweep.csv" "$root/whole_sweep/sweep.csv"

# 2. Slurm.
skip() {
  echo "cluster: SKIPPED: the Slurm test: $*"
  if [ "${PPB_REQUIRE_CLUSTER:-0}" = 1 ]; then
    echo "cluster: FAIL: PPB_REQUIRE_CLUSTER=1 and the Slurm test could not run"
    exit 1
  fi
  [ $fails = 0 ] && echo "cluster: GNU parallel passed; Slurm not tested" && exit 0
  echo "cluster: FAIL"
  exit 1
}
[ "$(id -u)" = 0 ] || skip "not root (slurmd must run as root to start job steps)"
timeout 600 bash scripts/deps.sh --cluster ||
  { echo "cluster: FAIL: slurm-wlm and munge could not be installed"; exit 1; }

c=$root/slurm
mkdir -p "$c/munge" "$c/state" "$c/spool" "$c/log"
chmod 700 "$c/munge"
dd if=/dev/urandom of="$c/munge/munge.key" bs=1024 count=1 status=none
chmod 600 "$c/munge/munge.key"
pids=()
stop() {
  local p
  [ -n "${SLURM_CONF:-}" ] && timeout 10 scancel --quiet --user="$(id -un)" 2>/dev/null || true
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do
    timeout 15 tail --pid="$p" -f /dev/null 2>/dev/null || kill -9 "$p" 2>/dev/null || true
  done
}
logs() {
  local f
  for f in "$c"/log/* "$c"/munge/log "$root"/*/logs/*; do
    [ -f "$f" ] && { echo "--- $f"; tail -n 20 "$f"; }
  done
}
trap 'rc=$?; stop; [ $rc = 0 ] || logs; exit $rc' EXIT

munged --foreground --force --socket="$c/munge/sock" --key-file="$c/munge/munge.key" \
  --pid-file="$c/munge/pid" --log-file="$c/munge/log" --seed-file="$c/munge/seed" \
  > "$c/log/munged.out" 2>&1 &
pids+=($!)
timeout 20 bash -c "until [ -S '$c/munge/sock' ]; do sleep 0.2; done" || skip "munged did not start"

host=$(hostname -s)
# slurmd -C prints this node as slurm.conf names it (CPUs, sockets, cores, memory).
node=$(slurmd -C | head -n 1)
cat > "$c/slurm.conf" <<EOF
# A one-node cluster for tests/cluster.sh, on this host only (loopback).
ClusterName=ppbench
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$c/munge/sock
StateSaveLocation=$c/state
SlurmdSpoolDir=$c/spool
SlurmctldPidFile=$c/slurmctld.pid
SlurmdPidFile=$c/slurmd.pid
SlurmctldLogFile=$c/log/slurmctld.log
SlurmdLogFile=$c/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
KillWait=5
MinJobAge=600
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$c/slurm.conf
slurmctld -D -f "$SLURM_CONF" > "$c/log/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" > "$c/log/slurmd.out" 2>&1 &
pids+=($!)
timeout 60 bash -c 'until [ "$(sinfo -h -o %T 2>/dev/null)" = idle ]; do sleep 0.5; done' ||
  { echo "cluster: FAIL: the Slurm node did not become idle"; exit 1; }
say "Slurm cluster up: node $host, $(sinfo -h -o %c) CPUs"

# wait_job ID: until the job has left the queue; then its state must be COMPLETED.
wait_job() {
  timeout 300 bash -c "while [ -n \"\$(squeue -h -j $1 -o %i 2>/dev/null)\" ]; do sleep 0.5; done" ||
    { echo "cluster: FAIL: job $1 still queued after 300 s"; exit 1; }
  local st
  st=$(scontrol show job "$1" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
  echo "job $1: $st"
  [ "$st" = COMPLETED ] || { echo "cluster: FAIL: job $1 ended $st"; exit 1; }
}
merge_of() { sed -n 's/^submitted: merge job \([0-9]*\).*/\1/p' <<< "$1"; }
array_of() { sed -n 's/^submitted: array job \([0-9]*\).*/\1/p' <<< "$1"; }

# 2a. The sweep: 4 array tasks and the merge job after them.
say "Slurm: the sweep as a 4-task array"
out=$(timeout 120 "$ppbench" slurm --shards 4 "${sweep_set[@]}" --out "$root/sweep" --submit \
  "$sweep_cfg")
echo "$out"
wait_job "$(merge_of "$out")"
same "$root/sweep/result/sweep.csv" "$root/whole_sweep/sweep.csv"

# 2b. The Monte Carlo: task 4 killed while it runs, then the same command again.
say "Slurm: the Monte Carlo as a 4-task array"
cmd=("$ppbench" slurm --shards 4 "${mc_set[@]}" --out "$root/mc" --submit "$mc_cfg")
out=$(timeout 120 "${cmd[@]}")
echo "$out"
array=$(array_of "$out") old_merge=$(merge_of "$out")
timeout 120 bash -c "until [ \"\$(squeue -h -j ${array}_4 -o %T 2>/dev/null)\" = RUNNING ]; do
  sleep 0.1; done" || { echo "cluster: FAIL: task ${array}_4 never ran"; exit 1; }
scancel "${array}_4"
timeout 60 bash -c "while [ -n \"\$(squeue -h -j ${array}_4 -o %i 2>/dev/null)\" ]; do
  sleep 0.2; done"
echo "task ${array}_4: $(scontrol show job "${array}_4" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')" \
  "(killed while running), marker: $([ -e "$root/mc/done/4" ] && echo present || echo none)," \
  "tallies: $([ -e "$root/mc/shards/4/mc_tallies.bin" ] && echo present || echo none)"
[ ! -e "$root/mc/done/4" ] && [ ! -e "$root/mc/shards/4/mc_tallies.bin" ] ||
  { echo "cluster: FAIL: the killed task left a marker or tallies"; exit 1; }
echo "merge job $old_merge: $(squeue -h -j "$old_merge" -o '%T (%r)')"
say "Slurm: the same command again"
out=$(timeout 120 "${cmd[@]}")
echo "$out"
grep -q "^submitted: array job [0-9]*, task 4$" <<< "$out" ||
  { echo "cluster: FAIL: the re-run did not submit shard 4 alone"; exit 1; }
wait_job "$(merge_of "$out")"
same_outputs "$root/whole_mc" "$root/mc/result"
out=$(timeout 120 "${cmd[@]}")
echo "$out"
grep -q "^nothing to submit" <<< "$out" || { echo "cluster: FAIL: a third run submitted"; exit 1; }

# The merge refuses a shard of another job (a marker of another stamp).
echo "mc another-build" > "$root/mc/done/2"
if timeout 60 bash "$root/mc/merge.sh" 2> "$root/refused.txt"; then
  echo "cluster: FAIL: merge.sh took a shard of another job"; fails=1
else
  echo "merge.sh refused: $(cat "$root/refused.txt")"
fi

if [ $fails = 0 ]; then say "passed"; else say "FAIL"; exit 1; fi
