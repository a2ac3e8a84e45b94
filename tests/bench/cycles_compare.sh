#!/bin/sh
# volmorph against Blender Cycles 3.4 (issue 33), not a test. Three scenes (SCENE=default, cloud or fog):
# - default: the default scene's frame 12 (sdf mode, 125 voxels across) as a .vdb, extinction 60 per
#   world unit, albedo 0.8 times the Cd grid;
# - cloud: the procedural cloud of volmorph_bench_cloud (voxel 0.01, 180 across), extinction 30,
#   albedo 0.9;
# - fog (issue 56, held out: nothing was tuned on it): scenes/meshes/elephant.off voxelized at 128
#   across (voxel 1/128) and rendered as fog, extinction 40, albedo 0.8 times its Cd (white).
# Both are rendered with the same camera, medium, sun (travelling -1,-1,-0.5, irradiance 3, colour
# 1,0.95,0.9) and constant sky (radiance 0.3,0.35,0.45), 16 volume bounces by default. Cycles through
# tests/bench/cycles_render.py (the half-voxel shift and axes of NOTES.md). Prints each render's
# time, then the comparison over pixels with alpha > 0.1 (volmorph_bench_image_compare: |dY|, mean
# relative RGB difference, bias, relative RMSE).
# SHOT=1 (issue 34): the same with a floor (scenes/meshes/floor.obj scaled 8 times, reflectance 0.5),
# the sky map scenes/skies/sky.exr instead of the constant sky, and a sun 2 degrees across.
# usage: [SCENE=default|cloud|fog] [SHOT=1] [OUT=DIR] [CYCLES=0] [MIN_ALPHA=0.1]
#        tests/bench/cycles_compare.sh [BUILD_DIR [RES [CYCLES_SAMPLES [VOLMORPH_SAMPLES [BOUNCES]]]]]
#        defaults: build 320x180 256 256 16; OUT=DIR keeps the images there (volmorph.exr,
#        cycles.exr); CYCLES=0 renders volmorph alone and compares with OUT/cycles.exr as it is.
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

sky=0.3,0.35,0.45 fov=40
case ${SCENE:-default} in
    default)
        sed "s|meshes/|$src/scenes/meshes/|; s|skies/|$src/scenes/skies/|" "$src/scenes/bunny-to-knot.toml" >"$out/scene.toml"
        VOLMORPH_CACHE="$out/cache" "$vm" morph "$out/scene.toml" --frames 12 -o "$out/m.####.vdb" -q
        vdb=$out/m.0012.vdb voxel=0.008 color=Cd
        eye=0.6,0.9,2.6 lookat=0,0.45,0 extinction=60 albedo=0.8
        ;;
    cloud)
        "$build/tests/bench/volmorph_bench_cloud" "$out/cloud.vdb" 0.01 >/dev/null
        vdb=$out/cloud.vdb voxel=0.01 color=
        eye=0.3,0.6,2.6 lookat=0,0.4,0 extinction=30 albedo=0.9
        ;;
    fog)
        "$vm" voxelize "$src/scenes/meshes/elephant.off" -o "$out/fog.vdb" --resolution 128 -q
        vdb=$out/fog.vdb voxel=0.0078125 color=Cd
        eye=1.6,0.6,2.0 lookat=0,0,0 extinction=40 albedo=0.8
        ;;
    *) echo "SCENE is default, cloud or fog"; exit 2 ;;
esac

# The sky, and with SHOT=1 the floor and the soft sun, for each renderer.
vm_shot="--env $sky" cy_shot="--sky $sky"
if [ "${SHOT:-0}" = 1 ]; then
    awk '$1 == "v" { print "v", 8 * $2, 8 * $3, 8 * $4; next } { print }' \
        "$src/scenes/meshes/floor.obj" >"$out/floor.obj"
    vm_shot="--env-map $src/scenes/skies/sky.exr --prop $out/floor.obj --prop-color 0.5,0.5,0.5 --light-angle 2"
    cy_shot="--sky-map $src/scenes/skies/sky.exr --floor $out/floor.obj --floor-color 0.5,0.5,0.5 --sun-angle 2"
fi
# shellcheck disable=SC2086
/usr/bin/time -f "volmorph (%e s, $volmorph_samples samples, $bounces bounces)" \
    "$vm" render-vdb "$vdb" -o "$out/volmorph.exr" --grid density --translate $eye --lookat $lookat \
    --fov $fov --res "$res" --extinction $extinction --albedo $albedo --light 1,1,0.5,3,2.85,2.7 $vm_shot \
    --bounces "$bounces" --samples "$volmorph_samples" --threads 2 --float --no-layers >/dev/null
if [ "${CYCLES:-1}" != 0 ]; then
    /usr/bin/time -f "cycles (%e s, $cycles_samples samples, $bounces bounces)" \
        blender -b --factory-startup --python "$src/tests/bench/cycles_render.py" -- "$vdb" \
        "$out/cycles.exr" --voxel $voxel --color-grid "$color" --eye $eye --lookat $lookat --fov $fov \
        --res "$res" --extinction $extinction --albedo $albedo --sun=-1,-1,-0.5,3,1,0.95,0.9 $cy_shot \
        --bounces "$bounces" --samples "$cycles_samples" --threads 2 >"$out/blender.log" 2>&1 ||
        { tail -20 "$out/blender.log"; exit 1; }
    grep "cycles: rendered" "$out/blender.log" || true
fi
printf "volmorph vs cycles: "
"$compare" "$out/volmorph.exr" "$out/cycles.exr" 1 "${MIN_ALPHA:-0.1}"
