#!/bin/sh
# volmorph voxelize writes sdf, density and Cd that OpenVDB's own vdb_print and pyopenvdb read,
# with the voxel size and source recorded as metadata.
# usage: voxelize_readable.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
source_dir=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$volmorph" voxelize "$source_dir/tests/data/meshes/tetra_colors.ply" -o "$out/tetra.vdb" --voxel-size 0.05 -q
listing=$(vdb_print -l -m "$out/tetra.vdb")
for grid in sdf density Cd; do
    echo "$listing" | grep -q "Name: $grid" || { echo "vdb_print does not list grid $grid:"; echo "$listing"; exit 1; }
done
echo "$listing" | grep -q "volmorph_voxel_size: 0.05" || { echo "no voxel size metadata:"; echo "$listing"; exit 1; }

if /usr/bin/python3 -c 'import pyopenvdb' 2>/dev/null; then
    /usr/bin/python3 - "$out/tetra.vdb" <<'PY'
import sys
import pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1])
names = sorted(g.name for g in grids)
assert names == ["Cd", "density", "sdf"], names
sdf = [g for g in grids if g.name == "sdf"][0]
assert sdf.gridClass == vdb.GridClass.LEVEL_SET, sdf.gridClass
assert abs(sdf.transform.voxelSize()[0] - 0.05) < 1e-9
assert sdf["volmorph_source"].endswith("tetra_colors.ply"), sdf["volmorph_source"]
print("pyopenvdb reads", names)
PY
else
    echo "pyopenvdb not installed (Debian package python3-openvdb); checked with vdb_print only"
fi
echo "voxelize output readable"
