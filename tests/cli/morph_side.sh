#!/bin/sh
# volmorph morph --side source|target: one side alone, warped at each frame's t. On the analytic scene
# (a sphere into a cube through one box pair, an affine map x -> c(t) + s(t) x with c(t) = (1.5 t, 0, 0)
# and s(t) = 1 - 0.2 t): the source side at t = 0 is the full morph's frame 0 value for value, the
# target side at t = 1 the full morph's last frame; the source side at each t carries the sphere's
# density mass times s(t)^3 with its centroid at c(t) (a closed form), and the target side at t = 0 the
# cube's mass over 0.8^3 at the origin. In variational mode (no warp) --side is refused.
# usage: morph_side.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
scene=$2/scenes/sphere-to-box.toml
export VOLMORPH_CACHE="$out/cache"
"$volmorph" morph "$scene" -o "$out/both.####.vdb" -q
"$volmorph" morph "$scene" --side source -o "$out/source.####.vdb" -q
"$volmorph" morph "$scene" --side target -o "$out/target.####.vdb" -q
/usr/bin/python3 - "$out" <<'PY'
import sys
import pyopenvdb as vdb

out = sys.argv[1]


def density(path):
    return vdb.read(path, "density")


def values(grid):
    return sorted((item.min, item.max, item.value) for item in grid.citerOnValues())


def mass_and_centroid(grid):
    mass, moment = 0.0, [0.0, 0.0, 0.0]
    for item in grid.citerOnValues():
        lo, hi = item.min, item.max
        count = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1)
        w = item.value * count
        centre = grid.transform.indexToWorld([(lo[i] + hi[i]) / 2.0 for i in range(3)])
        mass += w
        for i in range(3):
            moment[i] += w * centre[i]
    return mass, [m / mass for m in moment]


assert values(density(out + "/source.0000.vdb")) == values(density(out + "/both.0000.vdb")), \
    "the source side at t = 0 differs from the morph's first frame"
assert values(density(out + "/target.0004.vdb")) == values(density(out + "/both.0004.vdb")), \
    "the target side at t = 1 differs from the morph's last frame"
sphere, _ = mass_and_centroid(density(out + "/source.0000.vdb"))
for frame in range(5):
    t = frame / 4.0
    s = 1.0 - 0.2 * t
    mass, centroid = mass_and_centroid(density(out + "/source.%04d.vdb" % frame))
    assert abs(mass / sphere - s ** 3) < 0.01 * s ** 3, (frame, mass / sphere, s ** 3)
    for i, want in enumerate((1.5 * t, 0.0, 0.0)):
        assert abs(centroid[i] - want) < 0.01, (frame, centroid, want)
cube, _ = mass_and_centroid(density(out + "/target.0004.vdb"))
mass, centroid = mass_and_centroid(density(out + "/target.0000.vdb"))
assert abs(mass / cube - 0.8 ** -3) < 0.01 * 0.8 ** -3, (mass / cube, 0.8 ** -3)
assert all(abs(c) < 0.01 for c in centroid), centroid
print("morph --side: each side alone, as the affine map carries it")
PY
# The variational mode warps no side: a clear refusal naming --side, and no file.
status=0
"$volmorph" morph "$2/scenes/dino-to-eight-variational.toml" --side source --frames 1 \
    -o "$out/variational.####.vdb" -q 2>"$out/err" || status=$?
[ "$status" -ne 0 ] || { echo "morph --side in variational mode did not fail" >&2; exit 1; }
grep -q -- "--side.*variational" "$out/err" || { cat "$out/err" >&2; exit 1; }
[ ! -e "$out/variational.0001.vdb" ] || { echo "a file was written" >&2; exit 1; }
