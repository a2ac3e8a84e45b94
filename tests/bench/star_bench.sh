#!/bin/sh
# Kent's star-shaped merge (issue 57), not a test: the time and peak memory of a star-mode surface
# morph (import, kernels, merge, 24 frames written as PLY) against an sdf-mode morph of the same
# pair at 256 voxels across over the same 24 frames (voxelizing both sides included, no cache),
# side by side, medians of RUNS; the merged mesh's size against V_A + V_B; and the intersecting
# triangle pairs of the half-way frame under arap and linear (volmorph_bench_self_intersections).
# The pair, both closed, genus 0 and star-shaped: CGAL's blobby (scenes/meshes/blobby.off) cut
# twice into four at its edges' midpoints (64,800 triangles, the same surface) and a bumpy ball,
# an icosahedron cut six times with each vertex at radius 1 + 0.25 sin(3x) cos(2y) sin(2z)
# (81,920 triangles).
# usage: tests/bench/star_bench.sh [BUILD_DIR [RUNS]]
set -eu
build=${1:-build}
runs=${2:-3}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
count=$build/tests/bench/volmorph_bench_self_intersections
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

/usr/bin/python3 - "$src/scenes/meshes/blobby.off" "$work" <<'PY'
import math, sys
path, out = sys.argv[1], sys.argv[2]
words = open(path).read().split()
nv, nf = int(words[1]), int(words[2])
vals = words[4:]
pts = [tuple(map(float, vals[3 * i:3 * i + 3])) for i in range(nv)]
k, tris = 3 * nv, []
for _ in range(nf):
    n = int(vals[k]); idx = list(map(int, vals[k + 1:k + 1 + n])); k += 1 + n
    tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, n - 1)]

def subdivide(pts, tris, levels, push=None):
    for _ in range(levels):
        mid, new = {}, []
        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                mid[key] = len(pts)
                p = tuple((pts[a][c] + pts[b][c]) / 2 for c in range(3))
                pts.append(push(p) if push else p)
            return mid[key]
        for a, b, c in tris:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return pts, tris

def write(name, pts, tris):
    with open("%s/%s.obj" % (out, name), "w") as f:
        f.writelines("v %.9g %.9g %.9g\n" % p for p in pts)
        f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in tris)
    print("%s: %d vertices, %d triangles" % (name, len(pts), len(tris)))

write("source", *subdivide(pts, tris, 2))
g = (1 + 5 ** 0.5) / 2
ico = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
       (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
         (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
def unit(p):
    r = math.sqrt(sum(c * c for c in p))
    return tuple(c / r for c in p)
bp, bt = subdivide([unit(p) for p in ico], faces, 6, unit)
def bump(d):
    r = 1 + 0.25 * math.sin(3 * d[0]) * math.cos(2 * d[1]) * math.sin(2 * d[2])
    return (r * d[0], r * d[1], r * d[2])
write("target", [bump(d) for d in bp], bt)
PY

. "$src/tests/bench/morph_measure.sh"
scene surface '[surface]
correspondence = "star"' >"$work/star.toml"
scene surface '[surface]
correspondence = "star"
interpolation = "linear"' >"$work/linear.toml"
scene sdf >"$work/sdf.toml"

"$vm" check "$work/star.toml" | grep -A1 "^surface"

set -- $(measure "$work/star.toml" "m.####.ply")
ts=$1 ms=$2
set -- $(measure "$work/sdf.toml" "v.####.vdb")
tv=$1 mv=$2
echo "surface (star, arap), 24 PLY frames: $ts s, peak $ms MB"
echo "sdf mode at 256 across, 24 .vdb frames: $tv s, peak $mv MB"
echo "ratio: $(echo "scale=2; $ts / $tv" | bc)x the sdf-mode morph's time"

"$vm" morph "$work/star.toml" --frames 12 -o "$work/a.####.ply" -q
"$vm" morph "$work/linear.toml" --frames 12 -o "$work/l.####.ply" -q
echo "half-way (frame 12), intersecting triangle pairs:"
"$count" "$work/a.0012.ply" "$work/l.0012.ply" | sed "s#$work/a.0012.ply#  arap#; s#$work/l.0012.ply#  linear#"
