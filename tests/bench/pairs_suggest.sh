#!/bin/sh
# Suggested pairs against none and the hand-made ones (issue 39), not a test: for each scene, the IoU
# of the source side alone warped to t = 1 (`volmorph morph --side source`, the scene's last frame)
# with the target's density (both as density >= 0.5), with the scene's own pairs, with no pairs, and
# with only `volmorph pairs suggest`'s.
# CGAL=1: instead, CGAL's dino to cow, elephant to camel and armadillo to lion-head (the meshes of Debian's
# libcgal-demo, fetched with apt-get download; each scaled and moved so that its bounding box is 1 across
# at its longest and centred on the origin, from `volmorph check`'s bounds; density mode, 128 across; they
# have no hand-made pairs, so "hand" is "none").
# usage: [CGAL=1] tests/bench/pairs_suggest.sh [BUILD_DIR [SCENE.toml ...]]   (default: the three scenes)
set -eu
build=${1:-build}
[ $# -gt 0 ] && shift
src=$(cd "$(dirname "$0")/../.." && pwd)
vm=$(cd "$build" && pwd)/bin/volmorph
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
if [ "${CGAL:-0}" = 1 ]; then
    (cd "$out" && apt-get download libcgal-demo >/dev/null && dpkg-deb -x libcgal-demo_*.deb deb &&
        tar xzf deb/usr/share/doc/libcgal-dev/data.tar.gz data/meshes)
    m=$out/data/meshes
    scene() { # NAME SOURCE "SCALE, TRANSLATE" TARGET "SCALE, TRANSLATE"
        printf '[source]\nmesh = "%s"\ntransform = { %s }\n[target]\nmesh = "%s"\ntransform = { %s }\n' \
            "$m/$2.off" "$3" "$m/$4.off" "$5" >"$out/$1.toml"
        printf '[volume]\nresolution = 128\n[blend]\nmode = "density"\n[frames]\nrange = "1-24"\n' >>"$out/$1.toml"
    }
    unit='scale = 1.0'
    scene dino-to-cow dino 'scale = 0.2461, translate = [0.0012, -0.1706, 0.0033]' cow "$unit"
    scene elephant-to-camel elephant "$unit" camel "$unit"
    scene armadillo-to-lion-head armadillo 'scale = 0.006609, translate = [-0.0001, -0.1418, -0.0001]' \
        lion-head "$unit"
    set -- "$out/dino-to-cow.toml" "$out/elephant-to-camel.toml" "$out/armadillo-to-lion-head.toml"
fi
[ $# -gt 0 ] || set -- "$src/scenes/bunny-to-knot.toml" "$src/scenes/dino-to-eight.toml" \
    "$src/scenes/cloud-to-bunny.toml"
export VOLMORPH_CACHE="${VOLMORPH_CACHE:-$out/cache}"
for scene in "$@"; do
    name=$(basename "$scene" .toml)
    dir=$(dirname "$scene")
    # Paths made absolute; [[pair]] tables (a header and its key lines) taken out for "none".
    sed "s|\"meshes/|\"$dir/meshes/|; s|\"volumes/|\"$dir/volumes/|; s|\"skies/|\"$dir/skies/|" "$scene" \
        >"$out/$name.hand.toml"
    awk '/^\[\[pair\]\]/ { skip = 1; next } skip && /^[a-z]/ { next } { skip = 0; print }' \
        "$out/$name.hand.toml" >"$out/$name.none.toml"
    "$vm" pairs suggest "$out/$name.none.toml" -o "$out/$name.suggested.toml" -q
    last=$(awk -F'"' '/^range/ { n = split($2, r, "-"); print r[n] }' "$scene")
    for variant in hand none suggested; do
        "$vm" morph "$out/$name.$variant.toml" --side source --frames "$last" \
            -o "$out/$name.$variant.####.vdb" -q
    done
    "$vm" morph "$out/$name.hand.toml" --side target --frames "$last" -o "$out/$name.target.####.vdb" -q
    /usr/bin/python3 - "$out" "$name" "$last" <<'PY'
import sys
import pyopenvdb as vdb

out, name, last = sys.argv[1], sys.argv[2], int(sys.argv[3])


def inside(path):
    grid = vdb.read(path, "density")
    cells = set()
    for item in grid.citerOnValues():
        if item.value < 0.5:
            continue
        lo, hi = item.min, item.max
        for i in range(lo[0], hi[0] + 1):
            for j in range(lo[1], hi[1] + 1):
                for k in range(lo[2], hi[2] + 1):
                    cells.add((i, j, k))
    return cells


target = inside("%s/%s.target.%04d.vdb" % (out, name, last))
row = []
for variant in ("hand", "none", "suggested"):
    s = inside("%s/%s.%s.%04d.vdb" % (out, name, variant, last))
    row.append("%s %.4f" % (variant, len(s & target) / len(s | target)))
print("%-16s IoU of the source side at t = 1 with the target: %s" % (name, ", ".join(row)))
PY
done
