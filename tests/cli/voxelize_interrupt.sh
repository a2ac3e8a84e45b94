#!/bin/sh
# Ctrl-C (SIGINT) and SIGTERM stop `volmorph voxelize` cleanly: exit status 130, a message, and no
# output file (neither at the final name nor a temporary one).
# usage: voxelize_interrupt.sh VOLMORPH SOURCE_DIR
set -u
volmorph=$1
source_dir=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# caught PID: true once the process catches SIGINT and SIGTERM (bits 2 and 15 of SigCgt). Before that a
# background job of a non-interactive shell ignores SIGINT, so the signal would test nothing.
caught() {
    mask=$(awk '/^SigCgt:/ { print $2 }' "/proc/$1/status" 2>/dev/null) || return 1
    [ -n "$mask" ] && [ $((0x$mask & 0x4002)) -eq $((0x4002)) ]
}

for signal in INT TERM; do
    # Large enough to take several seconds, so the signal arrives mid-way.
    "$volmorph" voxelize "$source_dir/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 1400 -q \
        2> "$out/stderr" &
    pid=$!
    i=0
    until caught "$pid"; do
        i=$((i + 1))
        [ $i -lt 3000 ] || { echo "SIG$signal: no handler after 60 s"; exit 1; }
        sleep 0.02
    done
    sleep 1 # into the voxelization (the mesh is read by then in a release build)
    kill -s "$signal" "$pid"
    wait "$pid"
    status=$?
    if [ "$status" -ne 130 ]; then
        echo "SIG$signal: exit status $status, expected 130"; cat "$out/stderr"; exit 1
    fi
    grep -q "interrupted; no output written" "$out/stderr" || { echo "no message:"; cat "$out/stderr"; exit 1; }
    leftovers=$(ls "$out" | grep -v '^stderr$' || true)
    if [ -n "$leftovers" ]; then echo "SIG$signal left files: $leftovers"; exit 1; fi
done
echo "interrupted cleanly by SIGINT and SIGTERM"
