#!/bin/sh
# volmorph against Blender Cycles 3.4 (issue 33), not a test: the default scene's frame 12 (sdf mode,
# 125 voxels across) as a .vdb, rendered by both with the same camera, medium (extinction 60 per world
# unit, albedo 0.8 times the Cd grid), sun (travelling -1,-1,-0.5, irradiance 3, colour 1,0.95,0.9) and
# a constant sky (radiance 0.3,0.35,0.45), 16 volume bounces. Cycles through tests/bench/cycles_render.py
# (the half-voxel shift and axes of NOTES.md). Prints each render's time, then the comparison over pixels
# with alpha > 0.1 (volmorph_bench_image_compare: |dY|, mean relative RGB difference).
# usage: tests/bench/cycles_compare.sh [BUILD_DIR [RES [CYCLES_SAMPLES [VOLMORPH_SAMPLES [BOUNCES]]]]]
#        defaults: build 320x180 256 256 16; OUT=DIR keeps the images there
set -eu
build=${1:-build}
res=${2:-320x180}
cycles_samples=${3:-256}
volmorph_samples=${4:-256}
bounces=${5:-16}
src=$(cd "$(dirname "$0")/../.." && pwd)
command -v blender >/dev/null 2>&1 || { echo "needs Blender (apt-get install blender)"; exit 1; }
vm=$build/bin/volmorph
compare=$build/tests/bench/volmorph_bench_image_compare
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"

sed "s|meshes/|$src/scenes/meshes/|" "$src/scenes/bunny-to-knot.toml" >"$out/scene.toml"
VOLMORPH_CACHE="$out/cache" "$vm" morph "$out/scene.toml" --frames 12 -o "$out/m.####.vdb" -q
vdb=$out/m.0012.vdb
eye=0.6,0.9,2.6 lookat=0,0.45,0 fov=40 sky=0.3,0.35,0.45

/usr/bin/time -f "volmorph (%e s, $volmorph_samples samples, $bounces bounces)" \
    "$vm" render-vdb "$vdb" -o "$out/volmorph.exr" --grid density --translate $eye --lookat $lookat \
    --fov $fov --res "$res" --extinction 60 --albedo 0.8 --light 1,1,0.5,3,2.85,2.7 --env $sky \
    --bounces "$bounces" --samples "$volmorph_samples" --threads 2 --float >/dev/null
/usr/bin/time -f "cycles (%e s, $cycles_samples samples, $bounces bounces)" \
    blender -b --factory-startup --python "$src/tests/bench/cycles_render.py" -- "$vdb" "$out/cycles.exr" \
    --voxel 0.008 --color-grid Cd --eye $eye --lookat $lookat --fov $fov --res "$res" --extinction 60 \
    --albedo 0.8 --sun=-1,-1,-0.5,3,1,0.95,0.9 --sky $sky --bounces "$bounces" --samples "$cycles_samples" \
    --threads 2 >"$out/blender.log" 2>&1 || { tail -20 "$out/blender.log"; exit 1; }
grep "cycles: rendered" "$out/blender.log" || true
printf "volmorph vs cycles: "
"$compare" "$out/volmorph.exr" "$out/cycles.exr" 1
