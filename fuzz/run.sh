#!/bin/sh
# Run fuzz targets one after another for EXECS executions each (default 10 M), or for SECONDS
# seconds each when SECONDS_EACH is set, recording the counts in OUT/<target>/default/fuzzer_stats.
# Usage: fuzz/run.sh OUT TARGET... (see docs/fuzzing.md)
set -e
out=$1; shift
limit="-E ${EXECS:-10000000}"
[ -n "$SECONDS_EACH" ] && limit="-V $SECONDS_EACH"
cd "$(dirname "$0")"
export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 AFL_NO_AFFINITY=1
mkdir -p "$out"
for t in "$@"; do
    rm -rf "$out/$t"
    cargo afl fuzz -i "corpus/$t" -o "$out/$t" $limit -t 2000 \
        "${CARGO_TARGET_DIR:-target}/release/$t" > "$out/$t.log" 2>&1
    grep -E 'execs_done|saved_crashes|saved_hangs' "$out/$t/default/fuzzer_stats" | tr -s ' ' | sed "s/^/$t /"
done
