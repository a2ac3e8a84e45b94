#!/bin/sh
# The program's two executables (tools/Main.h): bin/volmorph needs neither OpenImageIO's image
# library (and its codecs) nor Embree, and runs the light commands itself; it hands every other
# command line to libexec/volmorph/volmorph-image, which answers as the one program did (the same
# process: a signal sent to it reaches the command).
# usage: light_program.sh VOLMORPH SOURCE_DIR
set -eu
. "$(dirname "$0")/lib.sh"
needed=$(readelf -d "$volmorph" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
echo "$needed" | grep -q 'libOpenImageIO\.so\|libembree' &&
    { echo "bin/volmorph links the image libraries:"; echo "$needed"; exit 1; }
echo "$needed" | grep -q 'libopenvdb' || { echo "bin/volmorph links no OpenVDB? $needed"; exit 1; }
count=$(ldd "$volmorph" | wc -l)
[ "$count" -lt 80 ] || { echo "bin/volmorph loads $count shared libraries"; exit 1; }
# The light commands here, every other through the image executable.
"$volmorph" voxelize --help | grep -q -- '--resolution' || { echo "voxelize --help"; exit 1; }
"$volmorph" render --help | grep -q -- '--skip-existing' || { echo "render --help"; exit 1; }
"$volmorph" --help | grep -q 'render-vdb' || { echo "--help lists no render-vdb"; exit 1; }
"$volmorph" --help | grep -q 'voxelize' || { echo "--help lists no voxelize"; exit 1; }
"$volmorph" --version | grep -q '^volmorph ' || { echo "--version"; exit 1; }
set +e
"$volmorph" rendr >/dev/null 2>"$out/err"
status=$?
set -e
[ "$status" -eq 2 ] || { echo "a mistyped command: exit $status, expected 2"; cat "$out/err"; exit 1; }
"$volmorph" check "$src/scenes/sphere-to-box.toml" >/dev/null || { echo "check through the image executable"; exit 1; }
echo "bin/volmorph: $count shared libraries, no image library; the image commands through volmorph-image"
