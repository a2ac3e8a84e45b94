#!/bin/sh
# What a [timing] costs (issue 59), not a test: scenes/bunny-to-knot-sweep.toml (sdf mode, no
# pairs, a sweep with spread 0.5) against the same scene without its [timing], side by side: the
# 24 frames' morph (`volmorph morph -o .vdb`, the voxels cached by a first run) and, with RENDER=1,
# their render, each the median of RUNS runs, with the peak resident size.
# usage: [RUNS=3] [RENDER=1] tests/bench/timing_bench.sh [BUILD_DIR]
set -eu
build=${1:-build}
runs=${RUNS:-3}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export VOLMORPH_CACHE="$work/cache"
sed "s|meshes/|$src/scenes/meshes/|; s|skies/|$src/scenes/skies/|" \
    "$src/scenes/bunny-to-knot-sweep.toml" >"$work/sweep.toml"
sed '/^\[timing\]/,/^sweep/d' "$work/sweep.toml" >"$work/plain.toml"
"$vm" morph "$work/plain.toml" --frames 1 -o "$work/warm.####.vdb" -q # the voxels, cached
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
run() { # COMMAND SCENE -> "seconds MB", medians
    times="" peaks=""
    i=0
    while [ "$i" -lt "$runs" ]; do
        /usr/bin/time -f "%e %M" -o "$work/t" "$vm" "$1" "$work/$2.toml" \
            -o "$work/o/$2.####.$3" -q
        times="$times $(cut -d' ' -f1 "$work/t")" peaks="$peaks $(cut -d' ' -f2 "$work/t")"
        i=$((i + 1))
    done
    echo "$(echo "$times" | median) s, peak $(($(echo "$peaks" | median) / 1024)) MB"
}
for what in morph ${RENDER:+render}; do
    ext=vdb
    [ "$what" = render ] && ext=exr
    plain=$(run "$what" plain "$ext") sweep=$(run "$what" sweep "$ext")
    echo "$what, 24 frames: without [timing] $plain; with the sweep $sweep"
    echo "$plain $sweep" | awk '{ printf "  ratio %.2f\n", $6 / $1 }'
done
