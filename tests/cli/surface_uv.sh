#!/bin/sh
# Texture coordinates through a surface morph (issue 57): a cube with an atlas's seams (each face its
# own island of the texture, so a corner's vertex has three sets of coordinates) into the same cube
# moved, its coordinates another layout, by the identity:
# - the OBJ frames' vt, per triangle corner, are the source's at frame 1 and the target's at the
#   last (to the text's 9 digits);
# - the PLY frames hold MeshLab's per-face texcoord (at the frame's tau) and both ends'
#   (texcoord_source, texcoord_target) in every frame, as floats equal to the inputs'.
# usage: surface_uv.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VOLMORPH_CACHE="$out/cache"

/usr/bin/python3 - "$out" <<'PY'
import sys
out = sys.argv[1]
pts = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
def write(name, shift, layout):
    with open("%s/%s.obj" % (out, name), "w") as f:
        for p in pts:
            f.write("v %g %g %g\n" % tuple(c + s for c, s in zip(p, shift)))
        for i, q in enumerate(quads):  # face i: its own island
            for k in range(4):
                f.write("vt %.6f %.6f\n" % layout(i, k))
        for i, q in enumerate(quads):
            v = [q[k] + 1 for k in range(4)]
            t = [4 * i + k + 1 for k in range(4)]
            f.write("f %d/%d %d/%d %d/%d\n" % (v[0], t[0], v[1], t[1], v[2], t[2]))
            f.write("f %d/%d %d/%d %d/%d\n" % (v[0], t[0], v[2], t[2], v[3], t[3]))
corner = [(0, 0), (1, 0), (1, 1), (0, 1)]
write("a", (0, 0, 0), lambda i, k: ((i % 3 + 0.1 + 0.8 * corner[k][0]) / 3.0,
                                   (i // 3 + 0.1 + 0.8 * corner[k][1]) / 2.0))
write("b", (3, 0, 0), lambda i, k: (0.1 * i + 0.05 * corner[k][0], 0.5 + 0.25 * corner[k][1]))
PY

cat >"$out/scene.toml" <<EOF2
[source]
mesh = "a.obj"
[target]
mesh = "b.obj"
[volume]
resolution = 16
[blend]
mode = "surface"
[surface]
correspondence = "identity"
interpolation = "linear"
[frames]
range = "1-3"
output = "out/frame.####.exr"
EOF2

"$volmorph" morph "$out/scene.toml" -o "$out/m.####.obj" -q
"$volmorph" morph "$out/scene.toml" -o "$out/m.####.ply" -q
/usr/bin/python3 - "$out" "$src" <<'PY'
import sys
out, src = sys.argv[1], sys.argv[2]
sys.path.insert(0, src + "/tests/cli")
sys.dont_write_bytecode = True  # nothing written into the source tree
from surface_frames import read_obj_uvs, read_ply_uvs

a, b = read_obj_uvs(out + "/a.obj"), read_obj_uvs(out + "/b.obj")
assert len(a) == 36 and len(set(a)) == 24, "the source's atlas: 24 corners of islands"
def close(x, y, tol):
    return len(x) == len(y) and all(abs(p[0] - q[0]) <= tol and abs(p[1] - q[1]) <= tol
                                    for p, q in zip(x, y))
assert close(read_obj_uvs(out + "/m.0001.obj"), a, 1e-6), "frame 1's vt are not the source's"
assert close(read_obj_uvs(out + "/m.0003.obj"), b, 1e-6), "frame 3's vt are not the target's"
half = read_obj_uvs(out + "/m.0002.obj")
assert close(half, [((p[0] + q[0]) / 2, (p[1] + q[1]) / 2) for p, q in zip(a, b)], 1e-6)
for f in (1, 2, 3):
    sets = read_ply_uvs("%s/m.%04d.ply" % (out, f))
    assert sorted(sets) == ["texcoord", "texcoord_source", "texcoord_target"], sorted(sets)
    assert close(sets["texcoord_source"], a, 1e-6) and close(sets["texcoord_target"], b, 1e-6)
assert close(read_ply_uvs(out + "/m.0001.ply")["texcoord"], a, 1e-6)
assert close(read_ply_uvs(out + "/m.0003.ply")["texcoord"], b, 1e-6)
print("texture coordinates: the source's at frame 1, the target's at frame 3, both in every PLY")
PY
echo "surface uv: OBJ vt and PLY texcoord per corner, seams kept"
