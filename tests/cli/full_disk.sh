#!/bin/sh
# A full disk, simulated with a file-size limit (ulimit -f, SIGXFSZ ignored so writes fail with
# EFBIG as on a full disk): the output is refused with one message naming it, the exit status is 1,
# and neither the file nor its temporary is left behind.
# usage: full_disk.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

check() { # name of the output, then the command
    out=$1; shift
    set +e
    ( trap '' XFSZ; ulimit -f 16; exec "$@" ) >/dev/null 2>"$dir/err"
    status=$?
    set -e
    [ $status = 1 ] || { echo "$*: exit status $status, expected 1"; cat "$dir/err"; exit 1; }
    grep -q "$out" "$dir/err" || { echo "$*: the message does not name $out:"; cat "$dir/err"; exit 1; }
    [ ! -e "$out" ] || { echo "$*: left $out"; exit 1; }
    leftovers=$(ls "$dir" | grep partial || true)
    [ -z "$leftovers" ] || { echo "$*: left temporaries: $leftovers"; exit 1; }
    echo "  $(basename "$out"): $(head -1 "$dir/err")"
}

check "$dir/s.vdb" "$volmorph" voxelize "$2/scenes/meshes/sphere.obj" -o "$dir/s.vdb" --resolution 64 -q
"$volmorph" voxelize "$2/scenes/meshes/sphere.obj" -o "$dir/ok.vdb" --resolution 32 -q
check "$dir/f.exr" "$volmorph" render-vdb "$dir/ok.vdb" -o "$dir/f.exr" --grid density --res 640x360 --samples 1
check "$dir/seq.0001.exr" "$volmorph" render "$2/scenes/sphere-to-box.toml" --frames 1 -o "$dir/seq.####.exr" --no-cache -q
echo "full disk: every output refused cleanly"
