#!/bin/sh
# Ctrl-C (SIGINT) and SIGTERM stop `volmorph voxelize` cleanly: exit status 130, a message, and no
# output file (neither at the final name nor a temporary one).
# usage: voxelize_interrupt.sh VOLMORPH SOURCE_DIR
set -u
. "$(dirname "$0")/lib.sh"
source_dir=$src

for signal in INT TERM; do
    # Large enough to take several seconds, so the signal arrives mid-way.
    "$volmorph" voxelize "$source_dir/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 1400 -q \
        2> "$out/stderr" &
    pid=$!
    wait_caught "$pid"
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
