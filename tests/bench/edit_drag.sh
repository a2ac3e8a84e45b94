#!/bin/sh
# What a drag in the editor costs the user (issue 39: the new in-between on screen within 1 s, at
# 128 voxels across, median of 5, 2 cores): `volmorph edit` on the default scene at --resolution
# 128, its page in headless chromium (WebGL on the CPU through SwiftShader, sharing the 2 cores
# with the server: a workstation's GPU draws faster), pair 2's target origin dragged 5 times with
# the gizmo. Each time: from the gizmo's release to the frame that shows the new in-between drawn,
# split into the edit (request and new state), the mesh (Morpher::withPairs, the frame at t = 0.5,
# volumeToMesh, sending it, decoding it) and the drawing. Prints the JSON line of
# tests/browser/editor_test.mjs; leaves the page's screenshots in OUT.
# usage: tests/bench/edit_drag.sh [BUILD] [OUT]   (BUILD default build, OUT default /tmp/edit_drag)
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-build}
shots=${2:-/tmp/edit_drag}
set -- "$build/bin/volmorph" "$here"
. "$here/tests/cli/lib.sh"
mkdir -p "$shots"
default_scene "$out/scene.toml"
start_editor "$out/scene.toml" --resolution 128 -q
node "$src/tests/browser/editor_test.mjs" "$url" "$shots" 5
stop_editor 5
