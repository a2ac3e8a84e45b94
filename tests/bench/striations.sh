#!/bin/sh
# Striations from the shadow cache (issue 33): the default scene's frame 12, morphed at ACROSS voxels
# across, rendered by render-vdb through an orthographic window 100 voxels wide at the object's
# centre (4 pixels per voxel, one ray through each pixel centre, so nothing but the transmittance
# differs) with the scene's medium and sun, at shadow-cache spacings 2 (the old default) and 1 (the default),
# against the exact transmittance per sample (--shadow-cache 0). Prints each render's time and, per
# spacing, the difference of relative luminance Y to the exact render (mean, 99th percentile over
# pixels with alpha > 0.1) and the difference's power at periods from 2 pixels to 3 voxels.
# usage: tests/bench/striations.sh [BUILD_DIR [ACROSS...]]   (default: build, 125 500)
set -eu
build=${1:-build}
[ $# -gt 0 ] && shift
across_list=${*:-125 500}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
power=$build/tests/bench/volmorph_bench_image_compare
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

for across in $across_list; do
    voxel=$(awk -v n="$across" 'BEGIN { printf "%.6g", 0.008 * 125 / n }')
    sed "s|meshes/|$src/scenes/meshes/|; s|skies/|$src/scenes/skies/|; s|^voxel_size = .*|voxel_size = $voxel|" \
        "$src/scenes/bunny-to-knot.toml" >"$out/scene.toml"
    VOLMORPH_CACHE="$out/cache" "$vm" morph "$out/scene.toml" --frames 12 -o "$out/m.####.vdb" -q
    width=$(awk -v v="$voxel" 'BEGIN { printf "%.6g", 100 * v }')
    echo "== $across voxels across (voxel $voxel), window $width world units"
    for cache in 2 1 0; do
        /usr/bin/time -f "   shadow-cache $cache: %e s" "$vm" render-vdb "$out/m.0012.vdb" -o "$out/c$cache.exr" \
            --camera ortho --translate 0,0.45,5 --lookat 0,0.45,0 --frame "$width" --res 400x400 \
            --extinction 60 --albedo 0.8 --light 1,1,0.5,3,2.85,2.7 --samples 1 --grid density --float \
            --shadow-cache "$cache" >/dev/null
    done
    for cache in 2 1; do
        printf "   spacing %s vs exact: " "$cache"
        "$power" "$out/c$cache.exr" "$out/c0.exr" 4
    done
done
