#!/bin/bash
# Start (or stop) a single-node Slurm cluster on this machine for tests: munged, slurmctld and
# slurmd with a generated slurm.conf under DIR. Needs root and Debian's slurm-wlm and munge
# (`make test-slurm` installs them). Clients find it with SLURM_CONF=DIR/slurm.conf.
#
#   scripts/slurm/local-cluster.sh start DIR [CPUS]   # CPUS: slots to offer (default: nproc)
#   scripts/slurm/local-cluster.sh stop DIR
set -euo pipefail
cmd=${1:?start or stop} dir=${2:?directory}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
conf=$dir/slurm.conf
if [ "$cmd" = stop ]; then
    pids=()
    for p in slurmd slurmctld munged; do
        [ -f "$dir/$p.pid" ] && pids+=("$(cat "$dir/$p.pid")")
    done
    [ ${#pids[@]} -gt 0 ] && kill "${pids[@]}" 2>/dev/null || true
    # Wait for them to exit, so that the ports are free for the next cluster.
    for _ in $(seq 1 50); do
        alive=0
        for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
        [ $alive = 0 ] && exit 0
        sleep 0.1
    done
    kill -9 "${pids[@]}" 2>/dev/null || true
    exit 0
fi
host=$(hostname -s)
cpus=${3:-$(nproc)}
mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
# munge: a key of this cluster's own and a socket under DIR.
if [ ! -f "$dir/munge/munge.key" ]; then
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$dir/munge/munge.key"
fi
socket=$dir/munge/munge.socket
cat > "$conf" <<CONF
ClusterName=relume
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=${SLURMCTLD_PORT:-6817}
SlurmdPort=${SLURMD_PORT:-6818}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
JobRequeue=1
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=relume Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
munged --force --socket="$socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/seed"
export SLURM_CONF=$conf
slurmctld -i -f "$conf"
slurmd -f "$conf"
for _ in $(seq 1 60); do
    state=$(sinfo -h -o %T 2>/dev/null | head -1 || true)
    if [ "$state" = idle ]; then
        echo "slurm up: SLURM_CONF=$conf ($cpus slots on $host)"
        exit 0
    fi
    sleep 1
done
echo "slurm did not come up (node state: ${state:-none}); logs in $dir" >&2
tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
exit 1
