#!/bin/sh
# blend.mode = "surface" through the command line (issue 57): a closed tube and the same tube bent by
# 120 degrees (one connectivity, so the identity correspondence applies), red into blue, 33 frames at
# 24 fps, as-rigid-as-possible in-betweens.
# - check says which correspondence "auto" chose, and the sizes;
# - morph -o .ply: every frame the same vertex count and triangles; the first frame is the source
#   file's points and the last the target's, vertex for vertex (1e-6); the colours red and blue at the ends; each
#   vertex's vx vy vz (world units per second) within 1% of the central difference of its positions
#   over the neighbouring frames (1/24 s apart), which checks the units as well as the derivative;
# - morph -o .vdb: the in-between voxelized, with sdf, density, Cd and a vel grid no faster than the
#   fastest vertex;
# - render: frame 17 renders as a surface, the subject: its alpha all in the volume layer (no prop
#   here); with a shutter it blurs (another image) and keeps its coverage (the mean alpha within 5%).
# usage: surface_morph.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VOLMORPH_CACHE="$out/cache"

/usr/bin/python3 - "$out" <<'PY'
import math, sys
out = sys.argv[1]
rings, around, length, radius, bend = 21, 16, 4.0, 0.3, 2 * math.pi / 3
pts = []
for i in range(rings):
    for k in range(around):
        a = 2 * math.pi * k / around
        pts.append((length * i / (rings - 1), radius * math.cos(a), radius * math.sin(a)))
pts += [(0.0, 0.0, 0.0), (length, 0.0, 0.0)]
start, end = len(pts) - 2, len(pts) - 1
at = lambda i, k: i * around + k % around
tris = []
for i in range(rings - 1):
    for k in range(around):
        tris += [(at(i, k), at(i, k + 1), at(i + 1, k + 1)), (at(i, k), at(i + 1, k + 1), at(i + 1, k))]
for k in range(around):
    tris += [(start, at(0, k + 1), at(0, k)), (end, at(rings - 1, k), at(rings - 1, k + 1))]
rc = length / bend
def bent(p):
    phi, r = bend * p[0] / length, rc - p[1]
    return (r * math.sin(phi), rc - r * math.cos(phi), p[2])
for name, points in (("tube", pts), ("bent", [bent(p) for p in pts])):
    with open("%s/%s.obj" % (out, name), "w") as f:
        for p in points:
            f.write("v %.9g %.9g %.9g\n" % p)
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
PY
cat >"$out/scene.toml" <<'EOF'
[source]
mesh = "tube.obj"
color = [1, 0, 0]
[target]
mesh = "bent.obj"
color = [0, 0, 1]
[volume]
resolution = 48
[blend]
mode = "surface"
[surface]
interpolation = "arap"
[render]
resolution = [64, 36]
samples = 2
camera = { eye = [1.5, 1.5, 8], lookat = [1.5, 1.2, 0], fov = 40 }
[frames]
range = "1-33"
fps = 24
output = "out/frame.####.exr"
EOF

"$volmorph" check "$out/scene.toml" >"$out/check.txt"
grep -q "^surface identity correspondence (auto): 338 vertices, 672 triangles at every frame; arap" \
    "$out/check.txt" || { echo "check:"; cat "$out/check.txt"; exit 1; }

"$volmorph" morph "$out/scene.toml" -o "$out/m.####.ply" -q
/usr/bin/python3 - "$out" "$(dirname "$0")" <<'PY'
import sys
out = sys.argv[1]
sys.path.insert(0, sys.argv[2])
sys.dont_write_bytecode = True  # nothing written into the source tree
from surface_frames import read_frames, read_obj


frames = read_frames(out, 33)
# The importer may order vertices its own way (Assimp's welding): vertex i of the frames is the
# file's vertex at frame 1's position, and must be the target file's same vertex at the last frame.
tube, bent = read_obj(out + "/tube.obj")[0], read_obj(out + "/bent.obj")[0]
index = {tuple(round(c, 5) for c in p): j for j, p in enumerate(tube)}
order = [index[tuple(round(c, 5) for c in v[:3])] for v in frames[0][0]]
assert sorted(order) == list(range(len(tube))), "frame 1 is not the source's vertices"
for f, ref, colour in ((0, tube, (255, 0, 0, 255)), (32, bent, (0, 0, 255, 255))):
    worst = max(abs(v[c] - ref[j][c]) for v, j in zip(frames[f][0], order) for c in range(3))
    assert worst < 1e-6, "frame %d is %g from its file" % (f + 1, worst)
    assert all(v[6:] == colour for v in frames[f][0]), "colour of frame %d" % (f + 1)
fps = 24.0
for f in (8, 16, 24):
    lo, mid, hi = frames[f - 1][0], frames[f][0], frames[f + 1][0]
    fastest = 0.0
    worst = 0.0
    for a, m, b in zip(lo, mid, hi):
        diff = [(b[c] - a[c]) * fps / 2.0 for c in range(3)]
        speed = sum(d * d for d in diff) ** 0.5
        fastest = max(fastest, speed)
        worst = max(worst, sum((m[3 + c] - diff[c]) ** 2 for c in range(3)) ** 0.5)
    assert fastest > 1.0, fastest  # the tube's end travels about 3 world units in 32 frames
    assert worst < 0.01 * fastest, "frame %d: vx vy vz %g from the central difference (fastest %g)" % (
        f + 1, worst, fastest)
print("surface frames: connectivity kept, ends exact, velocity within 1% of the difference")
PY

"$volmorph" morph "$out/scene.toml" --frames 17 -o "$out/v.####.vdb" -q
/usr/bin/python3 - "$out" <<'PY'
import struct, sys
import pyopenvdb as vdb
out = sys.argv[1]
grids = {g.name: g for g in vdb.readAll("%s/v.0017.vdb" % out)[0]}
assert {"sdf", "density", "Cd", "vel"} <= set(grids), sorted(grids)
vel = grids["vel"]
assert vel.activeVoxelCount() > 1000, vel.activeVoxelCount()
data = open("%s/m.0017.ply" % out, "rb").read().split(b"end_header\n", 1)[1]
fastest = max(sum(c * c for c in struct.unpack_from("<3f", data, i * 28 + 12)) ** 0.5
              for i in range(338))
top = max(sum(c * c for c in item.value) ** 0.5 for item in vel.citerOnValues())
assert 0.5 * fastest < top <= fastest * 1.0001, (top, fastest)
PY

"$volmorph" render "$out/scene.toml" --frames 17 -o "$out/r.####.exr" -q
sed 's/^samples = 2$/samples = 16\nshutter = [-0.5, 0.5]/' "$out/scene.toml" >"$out/blur.toml"
"$volmorph" render "$out/blur.toml" --frames 17 -o "$out/b.####.exr" -q
# Channels: R G B A depth.Z direct.RGB emission.RGB indirect.RGB shadow.A volume.RGBA.
alphas() { oiiotool --stats "$1" | awk '/Stats Avg/ { print $6, $(NF - 1) }'; }
/usr/bin/python3 - "$(alphas "$out/r.0017.exr")" "$(alphas "$out/b.0017.exr")" <<'PY'
import sys
still, blur = ([float(v) for v in a.split()] for a in sys.argv[1:3])
assert still[0] > 0.05 and still[0] == still[1], still  # the surface, and the subject's layer
assert blur[0] == blur[1], blur
assert abs(blur[0] - still[0]) < 0.05 * still[0], (blur, still)
PY
cmp -s "$out/r.0017.exr" "$out/b.0017.exr" && { echo "the shutter changed nothing"; exit 1; }
echo "surface morph: check, meshes, voxels and renders (still and blurred)"
