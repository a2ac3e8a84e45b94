#!/bin/sh
# Surface morphs (issue 57), not a test: the time and peak memory of a surface-mode morph (import,
# correspondence, 24 frames written as PLY) against an sdf-mode morph of the same pair at 256
# voxels across over the same 24 frames (voxelizing both sides included, no cache), side by side,
# medians of RUNS. The pair: MESH subdivided SUBDIVISIONS times (each triangle into four at its
# edges' midpoints) and the same mesh moved by a known smooth map (a twist of 90 degrees about the
# vertical axis over the mesh's height and a bend of 60 degrees), so that both have one
# connectivity and the identity correspondence applies. Also prints the half-way frame's volume
# over the ends' under arap and under linear (a twist and a bend keep the volume), and the
# intersecting triangle pairs of frame 12 under each (volmorph_bench_self_intersections).
# usage: tests/bench/surface_bench.sh [BUILD_DIR [MESH [SUBDIVISIONS [RUNS]]]]
#        defaults: build scenes/meshes/bunny.obj 2 3 (58,784 triangles)
set -eu
build=${1:-build}
src=$(cd "$(dirname "$0")/../.." && pwd)
mesh=${2:-$src/scenes/meshes/bunny.obj}
levels=${3:-2}
runs=${4:-3}
vm=$build/bin/volmorph
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

/usr/bin/python3 - "$mesh" "$levels" "$work" <<'PY'
import math, sys
path, levels, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
pts, tris = [], []
lines = open(path).read().split("\n")
if path.endswith(".off"):
    words = " ".join(l.split("#")[0] for l in lines[1:]).split()
    nv, nf = int(words[0]), int(words[1])
    vals = words[3:]
    pts = [tuple(map(float, vals[3 * i:3 * i + 3])) for i in range(nv)]
    k = 3 * nv
    for _ in range(nf):
        n = int(vals[k]); idx = list(map(int, vals[k + 1:k + 1 + n])); k += 1 + n
        tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, n - 1)]
else:
    for l in lines:
        w = l.split()
        if w and w[0] == "v": pts.append(tuple(map(float, w[1:4])))
        if w and w[0] == "f":
            idx = [int(x.split("/")[0]) - 1 for x in w[1:]]
            tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1)]
for _ in range(levels):
    mid = {}
    def m(a, b):
        key = (min(a, b), max(a, b))
        if key not in mid:
            mid[key] = len(pts)
            pts.append(tuple((pts[a][c] + pts[b][c]) / 2 for c in range(3)))
        return mid[key]
    new = []
    for a, b, c in tris:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    tris = new
lo = [min(p[c] for p in pts) for c in range(3)]
hi = [max(p[c] for p in pts) for c in range(3)]
h = hi[1] - lo[1]
def moved(p):
    s = (p[1] - lo[1]) / h                       # 0 at the bottom, 1 at the top
    a = 0.5 * math.pi * s                        # the twist about the vertical axis
    x, z = p[0] * math.cos(a) - p[2] * math.sin(a), p[0] * math.sin(a) + p[2] * math.cos(a)
    b, r = math.pi / 3 * s, h / (math.pi / 3)    # the bend in x-y, the height kept as arc length
    return (x + r * (1 - math.cos(b)), lo[1] + r * math.sin(b), z)
for name, points in (("source", pts), ("target", [moved(p) for p in pts])):
    with open("%s/%s.obj" % (out, name), "w") as f:
        f.writelines("v %.9g %.9g %.9g\n" % p for p in points)
        f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tris)
print("%d vertices, %d triangles" % (len(pts), len(tris)))
PY

. "$src/tests/bench/morph_measure.sh"
scene surface >"$work/surface.toml"
scene surface '[surface]
interpolation = "linear"' >"$work/linear.toml"
scene sdf >"$work/sdf.toml"

set -- $(measure "$work/surface.toml" "m.####.ply")
ts=$1 ms=$2
set -- $(measure "$work/sdf.toml" "v.####.vdb")
tv=$1 mv=$2
echo "surface (arap, identity), 24 PLY frames: $ts s, peak $ms MB"
echo "sdf mode at 256 across, 24 .vdb frames:  $tv s, peak $mv MB"
echo "ratio: $(echo "scale=2; $ts / $tv" | bc)x the sdf-mode morph's time"

"$vm" morph "$work/surface.toml" --frames 1,12,24 -o "$work/a.####.ply" -q
"$vm" morph "$work/linear.toml" --frames 12 -o "$work/l.####.ply" -q
/usr/bin/python3 - "$work" <<'PY'
import struct, sys
w = sys.argv[1]
def volume(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in lines if l.startswith("element face")).split()[2])
    stride = 28 if "property uchar red" in lines else 24
    p = [struct.unpack_from("<3f", body, i * stride) for i in range(nv)]
    v = 0.0
    for k in range(nf):
        _, a, b, c = struct.unpack_from("<B3i", body, nv * stride + 13 * k)
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = p[a], p[b], p[c]
        v += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    return v / 6
ends = (volume(w + "/a.0001.ply") + volume(w + "/a.0024.ply")) / 2
print("frame 12's volume over the ends': arap %.4f, linear %.4f" % (
    volume(w + "/a.0012.ply") / ends, volume(w + "/l.0012.ply") / ends))
PY
echo "frame 12, intersecting triangle pairs:"
"$build/tests/bench/volmorph_bench_self_intersections" "$work/a.0012.ply" "$work/l.0012.ply" |
    sed "s#$work/a.0012.ply#  arap#; s#$work/l.0012.ply#  linear#"
