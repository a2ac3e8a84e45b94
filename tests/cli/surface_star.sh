#!/bin/sh
# Kent's star-shaped merge through the command line (issue 57), on two meshes the merge was not
# tuned on (CGAL's blobby and six-pointed star, scenes/meshes):
# - check says "star", the merged size as the inputs' vertices plus the crossings, and the kernel
#   points it found;
# - morph -o .ply: every frame the same vertices and triangles; frame 1 encloses the blob's volume
#   and has its area, the last frame the star's (a merged mesh is a refinement of each input, so
#   both agree to float rounding, 1e-5), the colours red and blue at the ends;
# - a point outside the star given as its kernel is refused at its file:line:col naming the mesh.
# usage: surface_star.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VOLMORPH_CACHE="$out/cache"

cat >"$out/scene.toml" <<EOF2
[source]
mesh = "$src/scenes/meshes/blobby.off"
color = [1, 0, 0]
[target]
mesh = "$src/scenes/meshes/star.off"
color = [0, 0, 1]
transform = { translate = [3, 0, 0] }
[volume]
resolution = 32
[blend]
mode = "surface"
[surface]
correspondence = "star"
[frames]
range = "1-9"
output = "out/frame.####.exr"
EOF2

"$volmorph" check "$out/scene.toml" >"$out/check.txt"
grep -q "^surface star correspondence: [0-9]* vertices (2041 of the inputs, [0-9]* where their edges cross)" \
    "$out/check.txt" || { echo "check:"; cat "$out/check.txt"; exit 1; }
grep -q "projected from .*: each mesh's deepest kernel point" "$out/check.txt" ||
    { echo "check:"; cat "$out/check.txt"; exit 1; }

"$volmorph" morph "$out/scene.toml" -o "$out/m.####.ply" -q
/usr/bin/python3 - "$out" "$src" <<'PY'
import sys
out, src = sys.argv[1], sys.argv[2]
sys.path.insert(0, src + "/tests/cli")
sys.dont_write_bytecode = True  # nothing written into the source tree
from surface_frames import check_ends, read_frames, read_off


frames = read_frames(out, 9)
ends = ((0, read_off(src + "/scenes/meshes/blobby.off", (0, 0, 0)), (255, 0, 0, 255)),
        (8, read_off(src + "/scenes/meshes/star.off", (3, 0, 0)), (0, 0, 255, 255)))
check_ends(frames, ends)
print("star merge: %d vertices; the ends enclose the inputs' volumes and areas" % len(frames[0][0]))
PY

sed 's/^correspondence = "star"$/correspondence = "star"\nkernel = { source = [-0.12, 0, 0.08], target = [30, 0, 0] }/' \
    "$out/scene.toml" >"$out/outside.toml"
if "$volmorph" check "$out/outside.toml" >/dev/null 2>"$out/err.txt"; then
    echo "a kernel outside the star was accepted"; exit 1
fi
grep -q "outside.toml:[0-9]*:[0-9]*: surface.kernel: .*star.off is not seen whole from (30, 0, 0)" "$out/err.txt" ||
    { echo "stderr:"; cat "$out/err.txt"; exit 1; }
echo "surface star: check, merged meshes on both inputs, a kernel outside refused"
