#!/bin/sh
# The disk correspondence through the command line (issue 57): a dome of rings (radius 1, its rim
# a 24-gon inscribed in the unit circle at y = 0) into a bumpy square sheet of quads (its rim on
# the square |x|, |z| = 1.5), each with one boundary loop, meshed unlike each other.
# - check says "disk" (auto: neither the identity nor closed) and the merged size;
# - morph -o .ply: every frame the same vertices and triangles; frame 1 has the dome's area and the
#   last the sheet's (the merged mesh covers each input whole; 1e-5, float rounding); boundary onto
#   boundary: the frames' boundary vertices lie on the dome's rim at frame 1 and on the sheet's at
#   the last (1e-5).
# usage: surface_disk.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VOLMORPH_CACHE="$out/cache"

/usr/bin/python3 - "$out" <<'PY'
import math, sys
out = sys.argv[1]
rings, around = 8, 24
pts = [(0.0, 1.0, 0.0)]
for i in range(1, rings + 1):
    polar = 0.5 * math.pi * i / rings
    for k in range(around):
        a = 2 * math.pi * k / around
        pts.append((math.sin(polar) * math.cos(a), math.cos(polar), math.sin(polar) * math.sin(a)))
v = lambda i, k: 1 + (i - 1) * around + k % around
tris = [(0, v(1, k + 1), v(1, k)) for k in range(around)]
for i in range(1, rings):
    for k in range(around):
        tris += [(v(i, k), v(i, k + 1), v(i + 1, k + 1)), (v(i, k), v(i + 1, k + 1), v(i + 1, k))]
n = 12
sheet = [(-1.5 + 3.0 * k / n, 0.4 * math.exp(-(((-1.5 + 3.0 * k / n) ** 2 + (-1.5 + 3.0 * i / n) ** 2))),
          -1.5 + 3.0 * i / n) for i in range(n + 1) for k in range(n + 1)]
s = lambda i, k: i * (n + 1) + k
quads = [(s(i, k), s(i + 1, k), s(i + 1, k + 1), s(i, k + 1)) for i in range(n) for k in range(n)]
for name, points, faces in (("dome", pts, tris), ("sheet", sheet, quads)):
    with open("%s/%s.obj" % (out, name), "w") as f:
        f.writelines("v %.9g %.9g %.9g\n" % p for p in points)
        f.writelines("f %s\n" % " ".join(str(i + 1) for i in face) for face in faces)
PY
cat >"$out/scene.toml" <<'EOF2'
[source]
mesh = "dome.obj"
[target]
mesh = "sheet.obj"
[volume]
resolution = 32
[blend]
mode = "surface"
[frames]
range = "1-5"
output = "out/frame.####.exr"
EOF2

"$volmorph" check "$out/scene.toml" >"$out/check.txt"
grep -q "^surface disk correspondence (auto): [0-9]* vertices (362 of the inputs, [0-9]* where their edges cross)" \
    "$out/check.txt" || { echo "check:"; cat "$out/check.txt"; exit 1; }

"$volmorph" morph "$out/scene.toml" -o "$out/m.####.ply" -q
/usr/bin/python3 - "$out" "$(dirname "$0")" <<'PY'
import sys
out = sys.argv[1]
sys.path.insert(0, sys.argv[2])
sys.dont_write_bytecode = True  # nothing written into the source tree
from surface_frames import measure, read_frames, read_obj


frames = read_frames(out, 5)
uses = {}
for a, b, c in frames[0][1]:
    for e in ((a, b), (b, c), (c, a)):
        k = tuple(sorted(e)); uses[k] = uses.get(k, 0) + 1
rim = {v for e, n in uses.items() if n == 1 for v in e}
dome, sheet = read_obj(out + "/dome.obj"), read_obj(out + "/sheet.obj")
for f, (pts, faces) in ((0, dome), (4, sheet)):
    got, want = measure(frames[f][0], frames[f][1])[1], measure(pts, faces)[1]
    assert abs(got / want - 1) < 1e-5, "frame %d's area %g, the input's %g" % (f + 1, got, want)
import math
chords = [((math.cos(2 * math.pi * k / 24), math.sin(2 * math.pi * k / 24)),
           (math.cos(2 * math.pi * (k + 1) / 24), math.sin(2 * math.pi * (k + 1) / 24))) for k in range(24)]


def to_chord(x, z, a, b):
    t = max(0.0, min(1.0, ((x - a[0]) * (b[0] - a[0]) + (z - a[1]) * (b[1] - a[1])) /
                     ((b[0] - a[0]) ** 2 + (b[1] - a[1]) ** 2)))
    return ((a[0] + t * (b[0] - a[0]) - x) ** 2 + (a[1] + t * (b[1] - a[1]) - z) ** 2) ** 0.5


for v in rim:
    x, y, z = frames[0][0][v][:3]
    off = min(to_chord(x, z, a, b) for a, b in chords)
    assert abs(y) < 1e-5 and off < 1e-5, ("off the dome's rim", x, y, z)
    x, y, z = frames[4][0][v][:3]
    height = 0.4 * math.exp(-(x * x + z * z))  # along a rim edge the sheet is its chord: 1e-3
    assert abs(y - height) < 1e-3 and abs(max(abs(x), abs(z)) - 1.5) < 1e-5, ("off the sheet's rim", x, y, z)
print("disk merge: %d vertices, %d on the boundary; the ends cover the inputs" % (len(frames[0][0]), len(rim)))
PY
echo "surface disk: check, merged meshes covering both inputs, boundary onto boundary"
