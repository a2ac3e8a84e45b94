#!/bin/sh
# One entry point for the README's Quick start: installs what is missing, builds, then
#   tools/run.sh demo   runs the main job on the default scene (scenes/bunny-to-knot.toml): the morph,
#                       one .vdb per frame in scenes/out/
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
    out=scenes/out/bunny-to-knot.####.vdb
    "$build/bin/volmorph" morph "$scene" -o "$out"
    echo
    echo "volmorph: the morph of $scene is in scenes/out/bunny-to-knot.0001.vdb ... .0024.vdb"
    echo "(grids density and Cd, one file per frame; the renderer that turns them into EXR frames is"
    echo "not built yet: view them with vdb_view, Houdini or Blender). The program is $build/bin/volmorph."
    ;;
test)
    cd "$build"
    ctest --output-on-failure --parallel "$jobs"
    ;;
esac
