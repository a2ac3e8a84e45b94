#!/bin/sh
# How soon a stop request is answered (the promise: within 1 s of SIGINT or SIGTERM), measured on an
# idle machine: tests/cli/render_interrupt.sh and tests/cli/edit_stop.sh run RUNS times (default 5),
# each case recording its latency (render-vdb mid-frame and in its shadow maps; render, morph and
# preview mid-morph; morph in its setup; a variational solve and frame; the editor during start-up,
# beside the test's own two busy loops, and during a slow frame's morph); then the median and the
# worst of each case. The tests themselves read no clock (a loaded machine answers later).
# usage: tests/bench/stop_latency.sh BUILD_DIR [RUNS]
set -eu
build=$(cd "$1" && pwd)
runs=${2:-5}
root=$(cd "$(dirname "$0")/../.." && pwd)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
i=0
while [ "$i" -lt "$runs" ]; do
    STOP_LATENCY_LOG=$log sh "$root/tests/cli/render_interrupt.sh" "$build/bin/volmorph" "$root" 1 1 >/dev/null ||
        { echo "run $i failed"; exit 1; }
    STOP_LATENCY_LOG=$log sh "$root/tests/cli/edit_stop.sh" "$build/bin/volmorph" "$root" 1 >/dev/null ||
        { echo "run $i failed (editor)"; exit 1; }
    i=$((i + 1))
done
echo "stop latency over $runs runs (seconds: median, worst):"
cut -d' ' -f2- "$log" | sort -u | while IFS= read -r case; do
    grep -F " $case" "$log" | cut -d' ' -f1 | sort -n | awk -v c="$case" '
        { a[NR] = $1 }
        END { m = NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2
              printf "  %-45s %.3f  %.3f\n", c, m, a[NR] }'
done
sort -n "$log" | tail -n 1 | awk '{ printf "worst of all: %.3f s (the promise: 1 s)\n", $1 }'
