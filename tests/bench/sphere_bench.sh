#!/bin/sh
# The spherical map (issue 57), not a test:
# 1. per mesh: the time of the map, its L2 stretch efficiency (Praun and Hoppe's measure: 1 = no
#    stretch), the triangles it turns over by the exact predicate, and its total area minus 4 pi
#    (volmorph_bench_sphere_param), for every closed genus-0 mesh among CGAL's demo meshes (Debian's
#    libcgal-demo, fetched with apt-get download; the others are reported as refused) and for CGAL's
#    bear cut into four at its edges' midpoints (110,592 triangles);
# 2. with MPL=DIR (a build of Hoppe's Mesh-processing-library: DIR/bin/unix holds MeshSimplify,
#    reverselines, Filterprog and SphereParam), Hoppe's own SphereParam on the same meshes named in
#    ANCHORED, side by side: its time and the stretch efficiency of its map by the same measure;
# 3. a sphere-mode surface morph (the correspondence and 24 PLY frames, arap) of two meshes no
#    point sees whole, CGAL's armadillo (52,000 triangles) and bunny00 (75,408), against an
#    sdf-mode morph of the same pair at 256 voxels across over the same 24 frames, side by side,
#    medians of RUNS; peak memory; the merged mesh's size against V_A + V_B; and the intersecting
#    triangle pairs of the half-way frame under arap and linear.
# usage: [MPL=DIR] tests/bench/sphere_bench.sh [BUILD_DIR [RUNS]]
set -eu
build=${1:-build}
runs=${2:-3}
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$build/bin/volmorph
param=$build/tests/bench/volmorph_bench_sphere_param
count=$build/tests/bench/volmorph_bench_self_intersections
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ANCHORED=${ANCHORED:-"hand blobby dino homer bull fandisk camel bear man armadillo"}

(cd "$work" && apt-get download libcgal-demo >/dev/null 2>&1 && dpkg-deb -x libcgal-demo_*.deb deb &&
    tar xzf deb/usr/share/doc/libcgal-dev/data.tar.gz data/meshes)
meshes=$work/data/meshes

/usr/bin/python3 - "$meshes/bear.off" "$work/bear4.off" <<'PY'
import sys
words = open(sys.argv[1]).read().split()
nv, nf = int(words[1]), int(words[2])
vals = words[4:]
pts = [tuple(map(float, vals[3 * i:3 * i + 3])) for i in range(nv)]
k, tris = 3 * nv, []
for _ in range(nf):
    n = int(vals[k]); idx = list(map(int, vals[k + 1:k + 1 + n])); k += 1 + n
    tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, n - 1)]
mid, new = {}, []
def m(a, b):
    key = (min(a, b), max(a, b))
    if key not in mid:
        mid[key] = len(pts)
        pts.append(tuple((pts[a][c] + pts[b][c]) / 2 for c in range(3)))
    return mid[key]
for a, b, c in tris:
    ab, bc, ca = m(a, b), m(b, c), m(c, a)
    new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
with open(sys.argv[2], "w") as f:
    f.write("OFF\n%d %d 0\n" % (len(pts), len(new)))
    f.writelines("%.9g %.9g %.9g\n" % p for p in pts)
    f.writelines("3 %d %d %d\n" % t for t in new)
PY

echo "== volmorph's spherical map, per mesh"
"$param" "$meshes"/*.off "$work/bear4.off" 2>"$work/refused.txt" | sed "s#$meshes/##; s#$work/##"
echo "($(grep -c "^$meshes/" "$work/refused.txt") meshes refused: not closed, not genus 0 or not manifold)"

if [ -n "${MPL:-}" ]; then
    echo "== Hoppe's SphereParam (anchor), same meshes"
    bin=$MPL/bin/unix
    for name in $ANCHORED; do
        /usr/bin/python3 "$src/tests/bench/sphere_anchor.py" to-m "$meshes/$name.off" "$work/$name.m"
        start=$(date +%s.%N)
        # Hoppe's meshtopm.sh (a progressive mesh by quadric simplification), then SphereParam.
        "$bin/MeshSimplify" "$work/$name.m" -minqem -vsgeom -dihallow -prog "$work/$name.prog" \
            -simplify >"$work/$name.base.m" 2>/dev/null &&
            "$bin/reverselines" "$work/$name.prog" >"$work/$name.rprog" &&
            "$bin/Filterprog" -fbase "$work/$name.base.m" -fprog "$work/$name.rprog" -pm \
                >"$work/$name.pm" 2>/dev/null &&
            "$bin/SphereParam" "$work/$name.pm" >"$work/$name.sph.m" 2>/dev/null || {
            echo "$name: SphereParam failed"
            continue
        }
        end=$(date +%s.%N)
        printf '%s: SphereParam %.2f s, ' "$name" "$(echo "$end - $start" | bc)"
        /usr/bin/python3 "$src/tests/bench/sphere_anchor.py" efficiency "$work/$name.sph.m"
    done
fi

echo "== sphere-mode morph against sdf mode: armadillo into bunny00"
cp "$meshes/armadillo.off" "$work/source.off"
cp "$meshes/bunny00.off" "$work/target.off"
. "$src/tests/bench/morph_measure.sh"
scene surface '[surface]
correspondence = "sphere"' | sed 's/\.obj"/.off"/' >"$work/sphere.toml"
scene surface '[surface]
correspondence = "sphere"
interpolation = "linear"' | sed 's/\.obj"/.off"/' >"$work/linear.toml"
scene sdf | sed 's/\.obj"/.off"/' >"$work/sdf.toml"
"$vm" check "$work/sphere.toml" | grep -A2 "^surface"
set -- $(measure "$work/sphere.toml" "m.####.ply")
ts=$1 ms=$2
set -- $(measure "$work/sdf.toml" "v.####.vdb")
tv=$1 mv=$2
echo "surface (sphere, arap), 24 PLY frames: $ts s, peak $ms MB"
echo "sdf mode at 256 across, 24 .vdb frames: $tv s, peak $mv MB"
echo "ratio: $(echo "scale=2; $ts / $tv" | bc)x the sdf-mode morph's time"
"$vm" morph "$work/sphere.toml" --frames 12 -o "$work/a.####.ply" -q
"$vm" morph "$work/linear.toml" --frames 12 -o "$work/l.####.ply" -q
echo "half-way (frame 12), intersecting triangle pairs:"
"$count" "$work/a.0012.ply" "$work/l.0012.ply" "$meshes/armadillo.off" "$meshes/bunny00.off" |
    sed "s#$work/a.0012.ply#  arap#; s#$work/l.0012.ply#  linear#; s#$meshes/#  input #"
