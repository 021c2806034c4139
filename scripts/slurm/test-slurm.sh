#!/bin/bash
# `make test-slurm`: bake a bundled pipeline on a real single-node Slurm cluster started on this
# machine, as a 4-task array per round plus merges (scripts/slurm/submit.sh), and check the
# merged bake is byte-identical to a single-process run. Then again, killing one array task
# mid-run with SIGKILL and requeueing it. Needs Debian's slurm-wlm and munge (make deps-apt)
# and root or sudo (the daemons). Prints the wall times.
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$(pwd)
bake=$repo/target/release/relume-bake
pipeline=pipelines/door-ajar.ron
n=4
sudo=$([ "$(id -u)" = 0 ] || echo sudo)
for t in slurmctld slurmd munged sbatch; do
    command -v $t >/dev/null || { echo "error: $t is missing: install slurm-wlm and munge (make deps-apt)" >&2; exit 1; }
done
work=$(mktemp -d /tmp/relume-slurm.XXXXXX)
cluster=$work/cluster
export SLURMCTLD_PORT=${SLURMCTLD_PORT:-16817} SLURMD_PORT=${SLURMD_PORT:-16818}
cleanup() {
    $sudo "$repo/scripts/slurm/local-cluster.sh" stop "$cluster" || true
    rm -rf "$work"
}
trap cleanup EXIT
$sudo env SLURMCTLD_PORT="$SLURMCTLD_PORT" SLURMD_PORT="$SLURMD_PORT" \
    "$repo/scripts/slurm/local-cluster.sh" start "$cluster" "$n"
export SLURM_CONF=$cluster/slurm.conf RELUME_BAKE=$bake

# The reference: one process.
t0=$(date +%s.%N)
"$bake" -q run "$pipeline" --out "$work/single" --no-cache
t1=$(date +%s.%N)
echo "single process: $(awk "BEGIN {printf \"%.1f\", $t1 - $t0}") s"

state() { scontrol show job "$1" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -1; }
wait_job() { # wait until job $1 is finished; fail unless COMPLETED
    local s
    for _ in $(seq 1 900); do
        s=$(state "$1")
        case "$s" in
        COMPLETED) return 0 ;;
        FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY | BOOT_FAIL | DEADLINE)
            echo "error: job $1 ended $s" >&2
            cat "$work"/slurm-*.out >&2 || true
            return 1 ;;
        esac
        sleep 0.5
    done
    echo "error: job $1 still $s after 450 s" >&2
    return 1
}
same() { # the merged bake equals the single-process one, file for file
    if diff -r "$work/single" "$1" >/dev/null; then
        echo "$2: merged bake byte-identical to the single-process run ($(ls "$1" | wc -l) files)"
    else
        echo "error: $2: the merged bake differs from the single-process run" >&2
        diff -r "$work/single" "$1" >&2 || true
        exit 1
    fi
}

# 1. A clean array bake.
t0=$(date +%s.%N)
ids=$(scripts/slurm/submit.sh "$pipeline" "$work/array" "$n" --chdir="$repo" --output="$work/slurm-%j.out")
echo "$ids"
wait_job "$(echo "$ids" | tail -1)"
t1=$(date +%s.%N)
echo "slurm, $n-task arrays and merges: $(awk "BEGIN {printf \"%.1f\", $t1 - $t0}") s wall (submit to last merge)"
same "$work/array" "slurm"

# 2. Kill one task of the first array mid-run (SIGKILL) and requeue it.
t0=$(date +%s.%N)
ids=$(scripts/slurm/submit.sh "$pipeline" "$work/requeued" "$n" --chdir="$repo" --output="$work/slurm-%j.out")
echo "$ids"
array=$(echo "$ids" | head -1 | sed 's/.*array \([0-9]*\),.*/\1/')
task=${array}_1
for _ in $(seq 1 600); do [ "$(squeue -h -j "$task" -o %T 2>/dev/null)" = RUNNING ] && break; sleep 0.1; done
sleep 1
[ "$(squeue -h -j "$task" -o %T)" = RUNNING ] || { echo "error: task $task is not running" >&2; exit 1; }
scancel --signal=KILL "$task"
for _ in $(seq 1 100); do
    s=$(state "$task")
    [ "$s" != RUNNING ] && [ "$s" != COMPLETING ] && break
    sleep 0.1
done
echo "task $task killed: $(state "$task")"
ls "$work/requeued.shards" | grep -q "form_factors.1-of-$n.shard" &&
    { echo "error: the killed task finished its shard before the kill" >&2; exit 1; }
scontrol requeue "$task"
scontrol update JobId="$task" StartTime=now # Slurm delays a requeued job by two minutes
wait_job "$(echo "$ids" | tail -1)"
t1=$(date +%s.%N)
restarts=$(scontrol show job "$task" | sed -n 's/.*Restarts=\([0-9]*\).*/\1/p')
[ "$restarts" -ge 1 ] || { echo "error: $task was not requeued (Restarts=$restarts)" >&2; exit 1; }
echo "slurm with $task killed and requeued (Restarts=$restarts): $(awk "BEGIN {printf \"%.1f\", $t1 - $t0}") s wall"
same "$work/requeued" "slurm, killed and requeued"
cmp "$work/array.shards/form_factors.1-of-$n.shard" "$work/requeued.shards/form_factors.1-of-$n.shard"
echo "the requeued task's shard is byte-identical to the clean run's"
