#!/bin/sh
# Blender 3.4 blurs a volmorph frame along its velocity grid as volmorph does (issue 36), not a test.
# A sphere (radius 0.5) carried by a point pair 2.4 world units along x over one second (frames 1-25
# at 24 fps) is morphed in MODE (density or sdf) to frame 13 (t = 0.5, at the origin) with
# `--preset blender` (grids density, color, velocity); then rendered by volmorph's render-vdb and by
# Cycles (tests/bench/cycles_render.py: Velocity Unit = Second, scale 1), still and with a shutter
# of one frame centred (0.1 world units of travel), from the same camera. The smear length L is
# measured from alpha alone: averaging over a shutter that translates the image by L convolves
# alpha with a box L wide, which adds L^2 / 12 to the variance along x of alpha's column sums, so
# L = sqrt(12 (var_blurred - var_still)) whatever the edge's profile. Prints both renderers' L, the
# closed form (speed x shutter, in pixels at the sphere's distance; perspective makes the near and
# far sides differ slightly), and FAIL when the two differ by more than 1 pixel. Exits 77
# (skipped) where Blender is not installed.
# usage: [MODE=density|sdf] [OUT=DIR] [RENDER=0] [RES=256] tests/bench/blender_motion_blur.sh
#        [BUILD_DIR [SAMPLES]]   (RENDER=0 measures the images already in OUT; defaults build 64)
#    or, as the test cli.blender_motion_blur: blender_motion_blur.sh VOLMORPH SOURCE_DIR (128 pixels
#        square, 32 samples: half a minute)
# Exits 1 when the smears differ by more than a pixel.
set -eu
command -v blender >/dev/null 2>&1 || { echo "Blender not installed: skipped"; exit 77; }
src=$(cd "$(dirname "$0")/../.." && pwd)
if [ -f "${1:-}" ]; then # as a test (tests/CMakeLists.txt): VOLMORPH SOURCE_DIR, small and quick
    vm=$1 samples=32 res=${RES:-128}
else
    vm=${1:-build}/bin/volmorph samples=${2:-64} res=${RES:-256}
fi
if [ -n "${OUT:-}" ]; then
    out=$OUT
    mkdir -p "$out"
else
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
fi
fov=30 eye=0,0,4 lookat=0,0,0 extinction=20 speed=2.4 fps=24

cat >"$out/scene.toml" <<EOF
[source]
mesh = "$src/scenes/meshes/sphere.obj"
transform = { translate = [-1.2, 0, 0] }
[target]
mesh = "$src/scenes/meshes/sphere.obj"
transform = { translate = [1.2, 0, 0] }
[volume]
voxel_size = 0.02
[[pair]]
type = "point"
source = { origin = [-1.2, 0, 0] }
target = { origin = [1.2, 0, 0] }
[blend]
mode = "${MODE:-density}"
[frames]
range = "1-25"
fps = $fps
output = "o.####.exr"
EOF
VOLMORPH_CACHE="$out/cache" "$vm" morph "$out/scene.toml" --frames 13 --preset blender \
    -o "$out/m.####.vdb" -q
vdb=$out/m.0013.vdb

render() { # NAME SHUTTER (frames; 0: still)
    blur=
    [ "$2" = 0 ] || blur="--shutter -$(echo "$2 / 2" | bc -l),$(echo "$2 / 2" | bc -l) --fps $fps"
    "$vm" render-vdb "$vdb" -o "$out/volmorph-$1.exr" --grid density --translate $eye \
        --lookat $lookat --fov $fov --res ${res}x$res --extinction $extinction --albedo 0.8 \
        --light 1,1,0.5,3,3,3 --samples "$samples" --threads 2 --float $blur >/dev/null
    vblur=
    [ "$2" = 0 ] || vblur="--velocity-grid velocity --shutter $2 --fps $fps"
    blender -b --factory-startup --python "$src/tests/bench/cycles_render.py" -- "$vdb" \
        "$out/cycles-$1.exr" --voxel 0.02 --eye $eye --lookat $lookat --fov $fov \
        --res ${res}x$res --extinction $extinction --albedo 0.8 --sun=-1,-1,-0.5,3 --bounces 0 \
        --samples "$samples" --threads 2 $vblur >"$out/blender-$1.log" 2>&1 ||
        { tail -20 "$out/blender-$1.log"; exit 1; }
}
if [ "${RENDER:-1}" != 0 ]; then
    render still 0
    render blurred 1
fi

# Alpha's column sums: their variance along x (pixels squared).
variance() {
    oiiotool --dumpdata:empty=0 "$1" | python3 -c '
import re, sys
sums = {}
for m in re.finditer(r"Pixel \((\d+), \d+\): *\S+ \S+ \S+ (\S+)", sys.stdin.read()):
    sums[int(m.group(1))] = sums.get(int(m.group(1)), 0.0) + float(m.group(2))
total = sum(sums.values())
mean = sum(x * w for x, w in sums.items()) / total
print("%.4f" % (sum((x - mean) ** 2 * w for x, w in sums.items()) / total))'
}
vs=$(variance "$out/volmorph-still.exr") vb=$(variance "$out/volmorph-blurred.exr")
cs=$(variance "$out/cycles-still.exr") cb=$(variance "$out/cycles-blurred.exr")
# Pixels per world unit at the sphere's distance (4), across a field of view of fov degrees.
closed=$(python3 -c "import math; print('%.3f' % ($speed / $fps * $res / (2 * 4 * math.tan(math.radians($fov) / 2))))")
python3 - "$vs" "$vb" "$cs" "$cb" "$closed" <<'PY'
import math, sys
vs, vb, cs, cb, closed = (float(v) for v in sys.argv[1:])
lv, lc = math.sqrt(max(0.0, 12 * (vb - vs))), math.sqrt(max(0.0, 12 * (cb - cs)))
print("alpha's variance along x (pixels^2): volmorph still %.2f blurred %.2f; cycles still %.2f "
      "blurred %.2f" % (vs, vb, cs, cb))
print("smear length: volmorph %.2f, cycles %.2f, closed form %.2f pixels" % (lv, lc, closed))
if abs(lv - lc) > 1.0:
    print("FAIL: the smears differ by more than 1 pixel")
    sys.exit(1)
print("PASS")
PY
