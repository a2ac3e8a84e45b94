#!/bin/sh
# One entry point for the README's Quick start: installs what is missing, builds, then
#   tools/run.sh demo   runs the main job on the default scene (scenes/bunny-to-knot.toml): the morph,
#                       rendered to one EXR per frame in scenes/out/
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
cmake --build "$build" --parallel "$jobs"

case "$mode" in
demo)
    scene=scenes/bunny-to-knot.toml
    "$build/bin/volmorph" check "$scene"
    echo
    "$build/bin/volmorph" render "$scene" -o scenes/out/bunny-to-knot.####.exr
    echo
    echo "volmorph: the morph of $scene is rendered to scenes/out/bunny-to-knot.0001.exr ... .0024.exr"
    echo "(half RGBA OpenEXR, linear, premultiplied). The program is $build/bin/volmorph."
    ;;
test)
    cd "$build"
    ctest --output-on-failure --parallel "$jobs"
    ;;
esac
