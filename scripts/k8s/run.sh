#!/bin/bash
# Run a sharded bake on Kubernetes: per round, the Indexed Job of shards, then the merge job,
# each waited for with kubectl. The rounds are the stages `relume-bake plan --shards N` splits
# (2 for a pipeline with form factors and an infinite-bounce transport).
#
#   scripts/k8s/run.sh ROUNDS [kubectl options...]
set -euo pipefail
rounds=${1:?usage: $0 ROUNDS [kubectl options...]}
shift
here=$(cd "$(dirname "$0")" && pwd)
for ((r = 1; r <= rounds; r++)); do
    kubectl "$@" delete job relume-bake-shards relume-bake-merge --ignore-not-found
    kubectl "$@" apply -f "$here/bake-indexed-job.yaml"
    kubectl "$@" wait --for=condition=complete --timeout=24h job/relume-bake-shards
    kubectl "$@" apply -f "$here/merge-job.yaml"
    kubectl "$@" wait --for=condition=complete --timeout=24h job/relume-bake-merge
    echo "round $r of $rounds merged"
done
