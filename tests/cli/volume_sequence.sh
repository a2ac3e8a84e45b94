#!/bin/sh
# volmorph morph of a volume sequence (a fog ball drifting one voxel along x per frame, frames 1-5
# written here) into a mesh, with no pairs: each output frame f reads input frame f, so its density
# near the ball is (1 - t) times that frame's ball, voxel for voxel; before and after the
# sequence the first and last files are held.
# usage: volume_sequence.sh VOLMORPH SOURCE_DIR
set -eu
. "$(dirname "$0")/lib.sh"
py=/usr/bin/python3
if ! $py -c 'import pyopenvdb' 2>/dev/null; then
    echo "pyopenvdb not installed (python3-openvdb): sequence not checked"
    exit 0
fi
$py - "$src/tests/data/volumes/fog_ball.vdb" "$out" <<'PY'
import sys
import pyopenvdb as vdb
ball = vdb.read(sys.argv[1], "density")
for f in range(1, 6):
    g = ball.deepCopy()
    g.transform = vdb.createLinearTransform(voxelSize=0.1)
    g.transform.translate((0.1 * f, 0.0, 0.0))
    vdb.write("%s/drift.%04d.vdb" % (sys.argv[2], f), grids=[g])
PY
volume_scene "drift.####.vdb" '[frames]
range = "0-6"
output = "o.####.exr"'
"$volmorph" morph "$out/scene.toml" -o "$out/m.####.vdb" -q --no-cache
$py - "$src/tests/data/volumes/fog_ball.vdb" "$out" <<'PY'
import sys
import pyopenvdb as vdb
ball = vdb.read(sys.argv[1], "density")
values = {item.min: item.value for item in ball.citerOnValues()}
for f in range(0, 6):
    t = f / 6.0
    held = min(max(f, 1), 5)
    frame = vdb.read("%s/m.%04d.vdb" % (sys.argv[2], f), "density")
    acc = frame.getConstAccessor()
    worst = 0.0
    for (i, j, k), v in values.items():
        got = acc.getValue((i + held, j, k))
        worst = max(worst, abs(got - (1.0 - t) * v))
    assert worst < 1e-5, "frame %d: off by %g from input frame %d" % (f, worst, held)
print("frames 0-5 read inputs 1,1,2,3,4,5")
PY
echo "volume sequence: each frame reads its own input frame, held outside the sequence"
