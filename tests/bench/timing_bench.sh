#!/bin/sh
# What a [timing] costs (issue 59), not a test: a scene with a sweep against the same scene without
# its [timing], the two run in turn (plain, swept, plain, swept, ...: a shared machine's drift hits
# both alike): the frames' morph (`volmorph morph -o .vdb`, the voxels cached by a first run) and,
# with RENDER=1, their render. Prints each side's median time and peak resident size and the median
# of the runs' ratios.
#   SCENE=bunny (default): scenes/bunny-to-knot-sweep.toml, the default scene (sdf mode, three
#         pairs) swept floor up with spread 0.5, 24 frames (the scene the timing was tuned on);
#   SCENE=dino: scenes/dino-to-eight.toml (density mode, four pairs, 30 frames) with a sweep added
#         here, nose to tail (z from -0.5 to 0.5), spread 0.5 (not looked at while tuning).
# usage: [RUNS=3] [RENDER=1] [SCENE=bunny|dino] tests/bench/timing_bench.sh [BUILD_DIR]
set -eu
build=${1:-build}
runs=${RUNS:-3}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export VOLMORPH_CACHE="$work/cache"
absolute() { sed "s|\"meshes/|\"$src/scenes/meshes/|; s|\"skies/|\"$src/scenes/skies/|" "$1"; }
case ${SCENE:-bunny} in
bunny)
    absolute "$src/scenes/bunny-to-knot-sweep.toml" >"$work/sweep.toml"
    sed '/^\[timing\]/,/^sweep/d' "$work/sweep.toml" >"$work/plain.toml"
    ;;
dino)
    absolute "$src/scenes/dino-to-eight.toml" >"$work/plain.toml"
    { cat "$work/plain.toml"; printf '\n[timing]\nspread = 0.5\n'
      printf 'sweep = { origin = [0, 0, -0.5], direction = [0, 0, 1], length = 1.0 }\n'; } >"$work/sweep.toml"
    ;;
*) echo "SCENE: bunny or dino" >&2; exit 2 ;;
esac
"$vm" check "$work/sweep.toml" >/dev/null
"$vm" morph "$work/plain.toml" --frames 1 -o "$work/warm.####.vdb" -q # the voxels, cached
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
once() { # COMMAND SCENE EXT -> "seconds kB"
    /usr/bin/time -f "%e %M" -o "$work/t" "$vm" "$1" "$work/$2.toml" -o "$work/o/$2.####.$3" -q
    cat "$work/t"
}
for what in morph ${RENDER:+render}; do
    ext=vdb
    [ "$what" = render ] && ext=exr
    plain="" swept="" ratios="" plainPeak="" sweptPeak=""
    i=0
    while [ "$i" -lt "$runs" ]; do
        set -- $(once "$what" plain "$ext") $(once "$what" sweep "$ext")
        plain="$plain $1" plainPeak="$plainPeak $2" swept="$swept $3" sweptPeak="$sweptPeak $4"
        ratios="$ratios $(echo "$1 $3" | awk '{ printf "%.3f", $2 / $1 }')"
        i=$((i + 1))
    done
    echo "$what (${SCENE:-bunny}): without [timing] $(echo "$plain" | median) s, peak" \
        "$(($(echo "$plainPeak" | median) / 1024)) MB; with the sweep $(echo "$swept" | median) s," \
        "peak $(($(echo "$sweptPeak" | median) / 1024)) MB"
    echo "  ratios of the runs:$ratios; median $(echo "$ratios" | median)"
done
