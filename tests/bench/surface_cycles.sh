#!/bin/sh
# A surface morph rendered as a surface (issue 57) against Blender Cycles 3.4, not a test: frame 12
# of scenes/blobby-to-star-surface.toml (its sun 2 degrees across, sky map and floor) rendered by
# `volmorph render` (the in-between through Embree: smooth-shaded, reflectance render.albedo times
# its vertex colours), and its mesh (`volmorph morph -o .ply`) by Cycles through
# tests/bench/cycles_render.py (the same camera, lights, floor and bounces; a Diffuse BSDF of the
# albedo times the PLY's colours, Blender's own vertex normals). Both at a fixed sample count, no
# denoising. Prints each render's time and the comparison over pixels with alpha > 0.1
# (volmorph_bench_image_compare: |dY|, mean relative RGB difference, bias, relative RMSE).
# usage: [OUT=DIR] tests/bench/surface_cycles.sh [BUILD_DIR [CYCLES_SAMPLES [VOLMORPH_SAMPLES]]]
#        defaults: build 256 256; OUT=DIR keeps the images there (volmorph.0012.exr, cycles.exr).
set -eu
build=${1:-build}
cycles_samples=${2:-256}
volmorph_samples=${3:-256}
src=$(cd "$(dirname "$0")/../.." && pwd)
command -v blender >/dev/null 2>&1 || { echo "needs Blender (apt-get install blender)"; exit 1; }
vm=$build/bin/volmorph
compare=$build/tests/bench/volmorph_bench_image_compare
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"

sed "s|meshes/|$src/scenes/meshes/|; s|skies/|$src/scenes/skies/|;
     s|^samples = .*|samples = $volmorph_samples|" \
    "$src/scenes/blobby-to-star-surface.toml" >"$out/scene.toml"
awk '$1 == "v" { print "v", 8 * $2, 8 * $3, 8 * $4; next } { print }' \
    "$src/scenes/meshes/floor.obj" >"$out/floor.obj"
"$vm" morph "$out/scene.toml" --frames 12 -o "$out/m.####.ply" -q
/usr/bin/time -f "volmorph (%e s, $volmorph_samples samples, 4 bounces)" \
    "$vm" render "$out/scene.toml" --frames 12 -o "$out/volmorph.####.exr" --noise 0 --threads 2 -q
/usr/bin/time -f "cycles (%e s, $cycles_samples samples, 4 bounces)" \
    blender -b --factory-startup --python "$src/tests/bench/cycles_render.py" -- "$out/m.0012.ply" \
    "$out/cycles.exr" --voxel 0.008 --eye 0.6,0.9,2.6 --lookat 0,0.45,0 --fov 40 --res 480x270 \
    --extinction 0 --albedo 0.8 --sun=-1,-1,-0.5,3,1,0.95,0.9 --sun-angle 2 \
    --sky-map "$src/scenes/skies/sky.exr" --floor "$out/floor.obj" --floor-color 0.5,0.5,0.5 \
    --bounces 4 --samples "$cycles_samples" --threads 2 >"$out/blender.log" 2>&1 ||
    { tail -20 "$out/blender.log"; exit 1; }
grep "cycles: rendered" "$out/blender.log" || true
printf "volmorph vs cycles: "
"$compare" "$out/volmorph.0012.exr" "$out/cycles.exr" 1 "${MIN_ALPHA:-0.1}"
