#!/bin/bash
# Submit a relume bake split into N shards to Slurm: per round (one per expensive stage:
# form factors, then an infinite-bounce transport), an array job of N tasks and a merge that
# waits for it; each round's array waits for the previous merge (afterok). Prints the job ids,
# the last merge's last.
#
# The merge depends on its array with afterany, not afterok: Slurm never satisfies afterok once
# a task has failed, even after that task is requeued and succeeds. The merge instead waits for
# requeued tasks itself and refuses missing shards by name (exit 7). A task that is retried or
# resubmitted keeps its shard when it is already there and intact, so submitting the same bake
# again after a failure recomputes only what is missing.
#
#   scripts/slurm/submit.sh PIPELINE OUT N [extra sbatch options...]
#
# RELUME_BAKE names the binary (default: relume-bake on PATH). OUT.shards holds the shards.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 PIPELINE OUT N [sbatch options...]" >&2
    exit 2
fi
pipeline=$1 out=$2 n=$3
shift 3
here=$(cd "$(dirname "$0")" && pwd)
bake=${RELUME_BAKE:-relume-bake}
export RELUME_BAKE=$bake RELUME_PIPELINE=$pipeline RELUME_OUT=$out
export RELUME_SHARDS=${RELUME_SHARDS:-$out.shards}
mkdir -p "$RELUME_SHARDS"
# Rounds: the stages the plan splits.
rounds=$("$bake" plan "$pipeline" --out "$out" --shards "$n" | grep -c '^round ' || true)
if [ "$rounds" -eq 0 ]; then
    echo "$pipeline: no stage of this pipeline is split; run it with sbatch --wrap '$bake run $pipeline --out $out'" >&2
    exit 3
fi
dep=()
for ((r = 1; r <= rounds; r++)); do
    array=$(sbatch --parsable --array=0-$((n - 1)) "${dep[@]}" "$@" "$here/bake-array.sbatch")
    merge=$(sbatch --parsable --dependency=afterany:"$array" --export=ALL,RELUME_ARRAY_JOB="$array" \
        "$@" "$here/merge.sbatch")
    echo "round $r: array $array, merge $merge"
    dep=(--dependency=afterok:"$merge")
done
echo "$merge"
