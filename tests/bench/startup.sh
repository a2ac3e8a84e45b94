#!/bin/sh
# A whole process's cost, start-up included: `volmorph voxelize` of a mesh held out of every tuning
# (scenes/meshes/elephant.off, CGAL's, as OBJ) against what an OpenVDB user runs,
# `vdb_tool -read M -mesh2ls dim=N -ls2fog -write OUT` (volmorph also writes the colour grid and a
# smooth density ramp), at N = 128 and 256 voxels across, RUNS times each (default 7), alternating;
# then the medians and their ratio. A second volmorph (BASE, e.g. an older build's bin/volmorph) is
# measured beside them when given. Also each program's start-up alone (`--help`: 0 work).
# usage: tests/bench/startup.sh BUILD_DIR [RUNS [BASE_VOLMORPH]]
set -eu
volmorph=$(cd "$1" && pwd)/bin/volmorph
runs=${2:-7}
base=${3:-}
root=$(cd "$(dirname "$0")/../.." && pwd)
command -v vdb_tool >/dev/null || { echo "vdb_tool missing (Debian's libopenvdb-tools)"; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# OFF -> OBJ (vdb_tool reads no OFF).
awk 'NF == 0 || /^#/ { next } !h { h = 1; next } !c { c = 1; nv = $1; nf = $2; next }
     nv > 0 { print "v", $1, $2, $3; nv--; next }
     nf > 0 { printf "f"; for (i = 2; i <= $1 + 1; i++) printf " %d", $i + 1; print ""; nf-- }' \
    "$root/scenes/meshes/elephant.off" >"$work/elephant.obj"
# seconds COMMAND...: its wall time; the bench stops if it fails.
seconds() {
    /usr/bin/time -f %e -o "$work/time" "$@" >/dev/null 2>"$work/err" || { echo "failed: $*" >&2; cat "$work/err" >&2; exit 1; }
    cat "$work/time"
}
median() { sort -n | awk '{ a[NR] = $1 } END { print (NR % 2 ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2) }'; }
for n in 128 256; do
    : >"$work/v" ; : >"$work/t" ; : >"$work/b"
    i=0
    while [ $i -lt "$runs" ]; do
        seconds "$volmorph" voxelize "$work/elephant.obj" -o "$work/v.vdb" --resolution $n -q >>"$work/v"
        seconds vdb_tool -read "$work/elephant.obj" -mesh2ls dim=$n -ls2fog -write "$work/t.vdb" >>"$work/t"
        [ -z "$base" ] || seconds "$base" voxelize "$work/elephant.obj" -o "$work/b.vdb" --resolution $n -q >>"$work/b"
        i=$((i + 1))
    done
    v=$(median <"$work/v"); t=$(median <"$work/t")
    printf "elephant at %d across: volmorph voxelize %.3f s, vdb_tool %.3f s: %.2fx" "$n" "$v" "$t" \
        "$(awk -v a="$v" -v b="$t" 'BEGIN { print a / b }')"
    [ -z "$base" ] || printf "; base %.3f s (%.2fx)" "$(median <"$work/b")" \
        "$(awk -v a="$(median <"$work/b")" -v b="$t" 'BEGIN { print a / b }')"
    echo
done
: >"$work/h"; : >"$work/b"
i=0
while [ $i -lt "$runs" ]; do
    seconds "$volmorph" voxelize --help >>"$work/h"
    [ -z "$base" ] || seconds "$base" voxelize --help >>"$work/b"
    i=$((i + 1))
done
printf "start-up alone (voxelize --help): %.3f s, %d shared libraries" "$(median <"$work/h")" "$(ldd "$volmorph" | wc -l)"
[ -z "$base" ] || printf "; base %.3f s, %d" "$(median <"$work/b")" "$(ldd "$base" | wc -l)"
echo
