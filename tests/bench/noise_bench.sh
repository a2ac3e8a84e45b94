#!/bin/sh
# Frames without grain (issue 56), not a test: how fast each way of rendering reaches a noise level,
# against the brute-force path tracer's converged image.
#
# Scenes (SCENE=default, cloud or dino):
# - default: the default scene's frame 12 (sdf mode, 125 voxels across, Cd) with its own shot: the
#   floor (reflectance 0.5), the sky map and the sun 2 degrees across, extinction 60, albedo 0.8;
# - cloud: the procedural cloud of volmorph_bench_cloud (voxel 0.01), extinction 30, albedo 0.9,
#   the sun and a constant sky;
# - dino: a density-mode in-between nobody tuned on, dino-to-eight's frame 15 (128 across), extinction
#   40, albedo 0.8, the sun and a constant sky.
# The reference: render-vdb with no noise target (noise 0: exactly that many samples, the unbiased
# path tracer) at REF_SAMPLES, twice with seeds 1 and 2, kept in
# ${XDG_CACHE_HOME:-~/.cache}/volmorph/noise-bench (volmorph_bench_noise_error takes the mean as the
# converged image and the difference's part out of each error in quadrature).
# Then, each timed (the whole render-vdb command, medians of RUNS):
# - brute force at BRUTE samples: its error, and the time to 1% extrapolated as 1/sqrt(samples);
# - the estimate's honesty: noise 0 at 16, 64 and 256 samples, the estimate against the error;
# - each noise target of TARGETS (default 0.05 0.02 0.01): time, error, estimate, samples spent.
# DENOISE=0 reaches the targets by samples alone (--no-denoise). REF_ONLY=1 makes the references and
# stops (their time is not measured: run it while the machine is busy, the timed part when it is idle).
# usage: [SCENE=default|cloud|dino] [RUNS=1] [TARGETS="0.05 0.02 0.01"] [DENOISE=0] [REF_ONLY=1]
#        tests/bench/noise_bench.sh [BUILD_DIR [REF_SAMPLES [RES [BOUNCES [BRUTE]]]]]
#        defaults: build 4096 320x180 16 256
set -eu
build=${1:-build}
ref_samples=${2:-4096}
res=${3:-320x180}
bounces=${4:-16}
brute=${5:-256}
runs=${RUNS:-1}
denoise=""
[ "${DENOISE:-1}" = 0 ] && denoise=--no-denoise
scene=${SCENE:-default}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
measure=$build/tests/bench/volmorph_bench_noise_error
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

sky="--env 0.3,0.35,0.45" fov=40
case $scene in
    default)
        sed "s|meshes/|$src/scenes/meshes/|; s|skies/|$src/scenes/skies/|" "$src/scenes/bunny-to-knot.toml" >"$work/scene.toml"
        VOLMORPH_CACHE="$work/cache" "$vm" morph "$work/scene.toml" --frames 12 -o "$work/m.####.vdb" -q
        vdb=$work/m.0012.vdb eye=0.6,0.9,2.6 lookat=0,0.45,0 extinction=60 albedo=0.8
        awk '$1 == "v" { print "v", 8 * $2, 8 * $3, 8 * $4; next } { print }' \
            "$src/scenes/meshes/floor.obj" >"$work/floor.obj"
        sky="--env-map $src/scenes/skies/sky.exr --prop $work/floor.obj --prop-color 0.5,0.5,0.5 --light-angle 2"
        ;;
    cloud)
        "$build/tests/bench/volmorph_bench_cloud" "$work/m.vdb" 0.01 >/dev/null
        vdb=$work/m.vdb eye=0.3,0.6,2.6 lookat=0,0.4,0 extinction=30 albedo=0.9
        ;;
    dino)
        sed "s|meshes/|$src/scenes/meshes/|" "$src/scenes/dino-to-eight.toml" >"$work/scene.toml"
        VOLMORPH_CACHE="$work/cache" "$vm" morph "$work/scene.toml" --frames 15 -o "$work/m.####.vdb" -q
        vdb=$work/m.0015.vdb eye=1.8,0.9,1.2 lookat=0,0.1,0 extinction=40 albedo=0.8 fov=35
        ;;
    *) echo "SCENE is default, cloud or dino"; exit 2 ;;
esac

# One render: prints its seconds (wall clock of the whole command).
render() { # OUT SAMPLES NOISE SEED
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$vm" render-vdb "$vdb" -o "$1" --grid density --translate $eye --lookat $lookat --fov $fov \
        --res "$res" --extinction $extinction --albedo $albedo --light 1,1,0.5,3,2.85,2.7 $sky \
        --bounces "$bounces" --samples "$2" --noise "$3" --seed "$4" --float --no-layers $denoise >/dev/null
    echo "$(date +%s.%N) - $start" | bc
}
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
timed() { # OUT SAMPLES NOISE: the median seconds of RUNS runs (seed 7)
    times=""
    i=0
    while [ $i -lt "$runs" ]; do times="$times $(render "$1" "$2" "$3" 7)"; i=$((i + 1)); done
    echo "$times" | median
}

cache=${XDG_CACHE_HOME:-$HOME/.cache}/volmorph/noise-bench
# The key: what decides the reference: the shot, and the volume, by the committed trees and files
# that make it (an OpenVDB file holds UUIDs that differ per write, so its bytes cannot be the key; a
# scene file's samples, noise and denoise lines are left out, render-vdb does not read them; the
# renderer's code is left out too: the reference is the converged image, whatever unbiased code
# renders it).
case $scene in
    default) inputs="HEAD:libvolmorph HEAD:scenes/meshes HEAD:scenes/skies" file=scenes/bunny-to-knot.toml ;;
    cloud) inputs="HEAD:libvolmorph HEAD:tests/bench/cloud.cpp HEAD:tests/unit/support" file= ;;
    dino) inputs="HEAD:libvolmorph HEAD:scenes/meshes" file=scenes/dino-to-eight.toml ;;
esac
# shellcheck disable=SC2086
key=$( { echo "$scene $res $bounces $ref_samples $sky" | sed "s|$work||g"
         git -C "$src" rev-parse $inputs
         [ -z "$file" ] || git -C "$src" show "HEAD:$file" | grep -Ev '^(samples|noise|denoise) *='; } |
       sha256sum | cut -c1-16)
mkdir -p "$cache"
for seed in 1 2; do
    ref=$cache/$key.ref$seed.exr
    if [ ! -f "$ref" ]; then
        echo "reference $seed: $ref_samples samples ..."
        "$vm" render-vdb "$vdb" -o "$work/ref.exr" --grid density --translate $eye --lookat $lookat --fov $fov \
            --res "$res" --extinction $extinction --albedo $albedo --light 1,1,0.5,3,2.85,2.7 $sky \
            --bounces "$bounces" --samples "$ref_samples" --seed "$seed" --float --no-layers >/dev/null
        mv "$work/ref.exr" "$ref"
    fi
done
[ "${REF_ONLY:-0}" = 1 ] && { echo "references: $cache/$key.ref1.exr, .ref2.exr"; exit 0; }
error() { "$measure" "$1" "$cache/$key.ref1.exr" "$cache/$key.ref2.exr"; }

echo "scene $scene, $res, $bounces bounces, reference $ref_samples samples x 2 seeds, $runs run(s)"
seconds=$(timed "$work/brute.exr" "$brute" 0)
line=$(error "$work/brute.exr")
rmse=$(echo "$line" | awk '{ print $2 }')
echo "brute force, $brute samples: $seconds s, $line"
to1=$(echo "$seconds * ($rmse / 0.01)^2" | bc -l)
printf "brute force to 1%%: %.1f s (extrapolated as 1/sqrt(samples))\n" "$to1"
for s in 16 64 256; do
    render "$work/h.exr" "$s" 0 7 >/dev/null
    echo "noise 0, $s samples: $(error "$work/h.exr")"
done
for target in ${TARGETS:-0.05 0.02 0.01}; do
    seconds=$(timed "$work/t.exr" 65536 "$target")
    line=$(error "$work/t.exr")
    rmse=$(echo "$line" | awk '{ print $2 }')
    brute_to=$(echo "$to1 * (0.01 / $target)^2" | bc -l)
    printf "noise %s: %s s, %s; brute force to %s: %.1f s, ratio %.1fx\n" "$target" "$seconds" \
        "$line" "$rmse" "$(echo "$to1 * (0.01 / $rmse)^2" | bc -l)" \
        "$(echo "$to1 * (0.01 / $rmse)^2 / $seconds" | bc -l)"
    : "$brute_to"
done
