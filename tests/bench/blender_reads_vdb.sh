#!/bin/sh
# Blender 3.4 reads a `volmorph morph --preset blender --half` frame with its grids (issue 35): a
# fog ball with temperature and vel morphed into a cube, imported as a Blender volume object whose
# grids must be density and temperature (float) and color and velocity (vector), loaded, with
# voxels. Exits 77 (skipped) where Blender is not installed.
# usage: blender_reads_vdb.sh VOLMORPH SOURCE_DIR
set -eu
command -v blender >/dev/null 2>&1 || { echo "Blender not installed: skipped"; exit 77; }
. "$(dirname "$0")/../cli/lib.sh"
volume_scene "$src/tests/data/volumes/fog_ball.vdb" '[frames]
range = "1-3"
output = "o.####.exr"'
"$volmorph" morph "$out/scene.toml" --frames 2 --preset blender --half -o "$out/b.####.vdb" -q
cat >"$out/check.py" <<'PY'
import sys
import bpy
path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.object.volume_import(filepath=path)
volume = bpy.context.active_object.data
volume.grids.load()
found = {g.name: g.data_type for g in volume.grids}
print("blender grids:", found)
expected = {"density": "FLOAT", "temperature": "FLOAT", "color": "VECTOR_FLOAT",
            "velocity": "VECTOR_FLOAT"}
for name, kind in expected.items():
    if found.get(name) != kind:
        print("missing or wrong:", name, found.get(name))
        sys.exit(1)
for g in volume.grids:
    g.load()
    if not g.is_loaded:
        print("not loaded:", g.name)
        sys.exit(1)
print("blender reads the frame")
PY
blender -b --factory-startup --python-exit-code 1 --python "$out/check.py" -- "$out/b.0002.vdb" \
    >"$out/log" 2>&1 || { cat "$out/log"; exit 1; }
grep -E "blender grids|blender reads" "$out/log"
