#!/bin/sh
# Two builds of volmorph timed side by side, rounds interleaved (old, new, old, new, ...) so that a
# slow spell of a shared machine hits both alike: the render of render_vs_vdb_render.sh (the bunny
# fog at 256 across, 640x360, one sample, shadows; whole commands) with vdb_render in the same
# rounds as the anchor, the morph-frame bench (tests/bench/warp_bench.cpp: one frame at t = 0.5
# at 256 across, sdf and density modes) and the warp bench at 16 pairs (exact and approximated). Prints each series' median, min and max, and the
# new/old ratio of medians. For a change that must not cost time (a refactoring).
# usage: tests/bench/compare_builds.sh OLD_BUILD NEW_BUILD [ROUNDS (default 7)]
#        each BUILD has bin/volmorph and tests/bench/volmorph_bench_warp; needs vdb_render
set -eu
old=$1
new=$2
rounds=${3:-7}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
root=$(cd "$(dirname "$0")/../.." && pwd)

"$new/bin/volmorph" voxelize "$root/scenes/meshes/bunny.obj" -o "$out/bunny.vdb" --resolution 256 -q
absorb=0.0077401   # as render_vs_vdb_render.sh: extinction 1 per world unit, albedo 0.8, voxel 0.0387
scatter=0.0309604
vm_args="render-vdb $out/bunny.vdb --translate 0,5,25 --lookat 0,4.8,0 --fov 40 --res 640x360
    --extinction 1 --albedo 0.8 --light 0.3,0.7,0.6 --samples 1 --step 0.5 --grid density --float"
vdb_args="-translate 0,5,25 -lookat 0,4.8,0 -fov 40 -res 640x360 -absorb $absorb,$absorb,$absorb
    -scatter $scatter,$scatter,$scatter -light 0.3,0.7,0.6,1,1,1 -name density -cutoff 1e-7 -step 1 -shadowstep 3"

seconds() { # command... : wall seconds of one run
    start=$(date +%s.%N); "$@" >/dev/null 2>&1; end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN { printf "%.4f\n", b - a }'
}
bench_ms() { # BUILD FILTER : the bench's real time in ms
    "$1/tests/bench/volmorph_bench_warp" --benchmark_filter="$2" --benchmark_repetitions=1 \
        --benchmark_format=json 2>/dev/null | sed -n 's/.*"real_time": \([0-9.e+]*\).*/\1/p' | head -n 1
}
for r in $(seq "$rounds"); do
    for side in old new; do
        eval build=\$$side
        # shellcheck disable=SC2086
        seconds "$build/bin/volmorph" $vm_args -o "$out/$side.exr" >>"$out/render-$side"
        bench_ms "$build" 'morphFrame/256/' >>"$out/sdf-$side"
        bench_ms "$build" 'morphFrameDensity/256/' >>"$out/density-$side"
        bench_ms "$build" '^exactWarp/16/' >>"$out/exact16-$side"
        bench_ms "$build" '^approximatedWarp/16/' >>"$out/approx16-$side"
    done
    # shellcheck disable=SC2086
    seconds vdb_render "$out/bunny.vdb" "$out/vdb.exr" $vdb_args >>"$out/render-vdb_render"
    echo "round $r of $rounds done" >&2
done
# The pixels, not the files: an EXR records its render time.
if [ "$(iinfo --hash "$out/old.exr" | sed -n 's/.*SHA-1: *//p')" = "$(iinfo --hash "$out/new.exr" | sed -n 's/.*SHA-1: *//p')" ]; then
    echo "render: the two builds' pixels are identical"
else
    echo "render: the two builds' pixels DIFFER"
fi
stats() { sort -g "$1" | awk '{a[NR]=$1} END {printf "median %.4g  min %.4g  max %.4g  (n=%d)", a[int((NR+1)/2)], a[1], a[NR], NR}'; }
median() { sort -g "$1" | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for series in render sdf density exact16 approx16; do
    unit=$([ $series = render ] && echo s || echo ms)
    echo "$series ($unit): old $(stats "$out/$series-old")"
    echo "$series ($unit): new $(stats "$out/$series-new")"
    lo=$(sort -g "$out/$series-old" | head -n 1)
    hi=$(sort -g "$out/$series-old" | tail -n 1)
    awk -v a="$(median "$out/$series-old")" -v b="$(median "$out/$series-new")" -v lo="$lo" -v hi="$hi" \
        'BEGIN { printf "%s: new / old = %.3f; the new median is %s the old series'"'"' spread\n", "'$series'", b / a,
                 (b >= lo && b <= hi) ? "within" : "OUTSIDE" }'
done
echo "vdb_render (s): $(stats "$out/render-vdb_render")"
