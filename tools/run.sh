#!/bin/sh
# One entry point for the README's Quick start: installs what is missing, builds, then
#   tools/run.sh demo   runs the main job on the default scene (scenes/bunny-to-knot.toml): the morph,
#                       rendered to one EXR per frame in scenes/out/, a contact sheet and a preview of
#                       the feature pairs
#   tools/run.sh test   runs the whole test suite (CTest: unit, cli and bad-input tests)
# Environment: BUILD_DIR (default build), JOBS (default: number of cores).
set -eu

here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"
mode=${1:-}
case "$mode" in
    demo|test) ;;
    *) echo "usage: tools/run.sh demo|test" >&2; exit 2 ;;
esac

build=${BUILD_DIR:-build}
jobs=${JOBS:-$(nproc 2>/dev/null || echo 2)}

sh tools/install-deps.sh

generator=""
if command -v ninja >/dev/null 2>&1 && [ ! -f "$build/Makefile" ]; then generator="-G Ninja"; fi
# shellcheck disable=SC2086
cmake -S . -B "$build" $generator -DCMAKE_BUILD_TYPE=Release -DVOLMORPH_BUILD_TESTS=ON >/dev/null
# The demo builds only what it runs (the program and the editor's page); the tests build the rest.
if [ "$mode" = demo ]; then
    cmake --build "$build" --parallel "$jobs" --target volmorph_cli
else
    cmake --build "$build" --parallel "$jobs"
fi

case "$mode" in
demo)
    scene=scenes/bunny-to-knot.toml
    out=scenes/out
    "$build/bin/volmorph" check "$scene"
    echo
    "$build/bin/volmorph" render "$scene" -o "$out/bunny-to-knot.####.exr"
    "$build/bin/volmorph" preview "$scene" --contact-sheet --from "$out/bunny-to-knot.####.exr" --columns 6 \
        --tile-width 200 -o "$out/bunny-to-knot.contact-sheet.png" -q
    "$build/bin/volmorph" preview "$scene" --frame 12 --sides -o "$out/bunny-to-knot.features.0012.png" -q
    echo
    echo "volmorph: the morph of $scene is rendered:"
    echo "  frames         $out/bunny-to-knot.0001.exr ... .0024.exr (half OpenEXR: RGBA, linear, premultiplied, and the layers volume, direct, indirect, emission, shadow, depth.Z)"
    echo "  contact sheet  $out/bunny-to-knot.contact-sheet.png"
    echo "  feature pairs  $out/bunny-to-knot.features.0012.png (frame 12; amber: at t, blue: source, pink: target)"
    echo "The program is $build/bin/volmorph (volmorph --help)."
    ;;
test)
    cd "$build"
    ctest --output-on-failure --parallel "$jobs"
    ;;
esac
