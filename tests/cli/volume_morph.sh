#!/bin/sh
# volmorph morph of a volume input (a fog ball with temperature, vel and a bool grid) into a mesh:
# --preset blender --half writes Blender's names (color, velocity: the morph's own) with the carried
# temperature and the input's vel (as velocity_carried), 16-bit floats and the frame, t and fps;
# --preset houdini in sdf mode writes a `surface` level set.
# usage: volume_morph.sh VOLMORPH SOURCE_DIR
set -eu
. "$(dirname "$0")/lib.sh"
volume_scene "$src/tests/data/volumes/fog_ball.vdb" '[blend]
grids = { temperature = "smoothstep" }
[frames]
range = "1-3"
fps = 25
output = "o.####.exr"'
"$volmorph" morph "$out/scene.toml" --frames 2 --preset blender --half -o "$out/b.####.vdb" -q
expect_files "$out" "b.0002.vdb scene.toml"
listing=$(vdb_print -l -m "$out/b.0002.vdb")
for name in density color temperature velocity velocity_carried; do
    echo "$listing" | grep -q "^Name: $name\$" || { echo "no grid $name:"; echo "$listing"; exit 1; }
done
echo "$listing" | grep -q "^Name: ids" && { echo "the bool grid was carried"; exit 1; }
for meta in "volmorph_fps: 25" "volmorph_t: 0.5" "volmorph_frame: 2"; do
    echo "$listing" | grep -q "$meta" || { echo "no $meta"; echo "$listing"; exit 1; }
done
if /usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null; then
    /usr/bin/python3 - "$out/b.0002.vdb" <<'PY'
import sys
import pyopenvdb as vdb
grids, _ = vdb.readAll(sys.argv[1])
names = sorted(g.name for g in grids)
assert names == ["color", "density", "temperature", "velocity", "velocity_carried"], names
for g in grids:
    assert g.metadata.get("is_saved_as_half_float"), (g.name, "not half")
heat = [g for g in grids if g.name == "temperature"][0]
assert heat.activeVoxelCount() > 100, heat.activeVoxelCount()
PY
fi
# sdf mode, Houdini's names: the fog's derived level set is written as `surface`.
sed -i 's/^grids = { temperature = "smoothstep" }$/mode = "sdf"/' "$out/scene.toml"
"$volmorph" morph "$out/scene.toml" --frames 2 --preset houdini -o "$out/h.####.vdb" -q
listing=$(vdb_print -l "$out/h.0002.vdb")
for name in surface density Cd temperature vel; do
    echo "$listing" | grep -q "^Name: $name\$" || { echo "no grid $name:"; echo "$listing"; exit 1; }
done
echo "volume morph: Blender's and Houdini's names, carried grids, half floats, frame metadata"
