#!/bin/sh
# volmorph render-vdb: an EXR with the metadata and layers of the spec (RGBA alone with --no-layers),
# a PNG preview, and the same pixels bit for bit whatever the thread count.
# usage: render_vdb.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$volmorph" voxelize "$2/scenes/meshes/sphere.obj" -o "$out/sphere.vdb" --resolution 48 -q
common="--res 64x48 --samples 3 --light 1,1,1 --extinction 8 --grid density"
# shellcheck disable=SC2086
"$volmorph" render-vdb "$out/sphere.vdb" -o "$out/one.exr" --threads 1 --png "$out/one.png" $common >/dev/null
# shellcheck disable=SC2086
"$volmorph" render-vdb "$out/sphere.vdb" -o "$out/two.exr" --threads 2 $common >/dev/null
idiff -fail 0 -failpercent 0 -hardfail 0 "$out/one.exr" "$out/two.exr" >/dev/null \
    || { echo "--threads 1 and 2 differ"; idiff "$out/one.exr" "$out/two.exr"; exit 1; }
info=$(oiiotool --info -v "$out/one.exr")
for field in "half" "compression: \"zip\"" "chromaticities: 0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329" \
             "worldToCamera" "worldToNDC" "Software: \"volmorph" "volmorph:samples: 3" \
             "19 channel" "depth.Z (float)" "volume.A (half)" "indirect.B (half)" "shadow.A (half)"; do
    echo "$info" | grep -q "$field" || { echo "EXR lacks $field:"; echo "$info"; exit 1; }
done
# shellcheck disable=SC2086
"$volmorph" render-vdb "$out/sphere.vdb" -o "$out/rgba.exr" --no-layers $common >/dev/null
oiiotool --info "$out/rgba.exr" | grep -q "4 channel" || { echo "--no-layers wrote layers"; exit 1; }
# A sky map alone lights the volume (no default light then): some pixels lit, all finite.
"$volmorph" render-vdb "$out/sphere.vdb" -o "$out/sky.exr" --env-map "$2/scenes/skies/sky.exr" \
    --res 32x24 --samples 4 --extinction 8 --grid density --no-layers >/dev/null
stats=$(oiiotool "$out/sky.exr" --printstats)
echo "$stats" | grep -q "NanCount: 0 0 0 0" || { echo "non-finite pixels under the sky map"; exit 1; }
echo "$stats" | grep "Stats Max" | awk '{ exit !($3 > 0.05) }' || { echo "the sky map lit nothing: $stats"; exit 1; }
# A floor prop (the unit square scaled 8 times) under a looking-down camera: the bottom row is floor,
# opaque; with --light-angle the run still works.
awk '$1 == "v" { print "v", 8 * $2, 8 * $3 - 0.4, 8 * $4; next } { print }' \
    "$2/scenes/meshes/floor.obj" >"$out/floor.obj"
"$volmorph" render-vdb "$out/sphere.vdb" -o "$out/prop.exr" --prop "$out/floor.obj" --prop-color 0.5,0.5,0.5 \
    --translate 0,1.5,3 --lookat 0,0,0 --res 32x24 --samples 2 --extinction 8 --grid density \
    --light-angle 2 --no-layers >/dev/null
oiiotool "$out/prop.exr" --cut 32x1+0+23 --printstats | grep "Stats Min" | awk '{ exit !($6 == 1) }' \
    || { echo "the floor prop is not opaque under the volume"; oiiotool "$out/prop.exr" --printstats; exit 1; }
[ -s "$out/one.png" ] || { echo "no PNG preview"; exit 1; }
[ "$(ls "$out" | grep -c partial || true)" -eq 0 ] || { echo "temporary files left"; exit 1; }
echo "render-vdb: deterministic across thread counts, metadata present"
