#!/bin/sh
# volmorph render SCENE: one EXR per frame; three chunks give the frames of a full run pixel for
# pixel; --skip-existing leaves finished frames alone and redoes a truncated one.
# usage: render_scene.sh VOLMORPH SOURCE_DIR
set -eu
. "$(dirname "$0")/lib.sh"
scene=$src/scenes/sphere-to-box.toml

"$volmorph" render "$scene" -o "$out/full/f.####.exr" -q
expect_files "$out/full" "f.0000.exr f.0001.exr f.0002.exr f.0003.exr f.0004.exr"
# Three chunks, as three farm tasks would run them (one with one thread): the frames of the full run.
"$volmorph" render "$scene" --frames 0-1 -o "$out/chunk/f.####.exr" -q
"$volmorph" render "$scene" --frames 2-3 -o "$out/chunk/f.####.exr" -q --threads 1
"$volmorph" render "$scene" --frames 4 -o "$out/chunk/f.####.exr" -q
for f in 0000 0001 0002 0003 0004; do
    idiff -fail 0 -failpercent 0 -hardfail 0 "$out/full/f.$f.exr" "$out/chunk/f.$f.exr" >/dev/null \
        || { echo "frame $f differs between chunk and full run"; exit 1; }
done
# A truncated frame is redone; a whole one is skipped.
head -c 100 "$out/full/f.0001.exr" > "$out/f1" && mv "$out/f1" "$out/full/f.0001.exr"
log=$("$volmorph" render "$scene" --frames 0-2 -o "$out/full/f.####.exr" --skip-existing)
echo "$log" | grep -q "frame 0: .* exists, skipped" || { echo "frame 0 not skipped:"; echo "$log"; exit 1; }
echo "$log" | grep -q "frame 1 (t=0.2500)" || { echo "frame 1 not redone:"; echo "$log"; exit 1; }
idiff -fail 0 -failpercent 0 -hardfail 0 "$out/full/f.0001.exr" "$out/chunk/../full/f.0001.exr" >/dev/null
oiiotool --info "$out/full/f.0001.exr" >/dev/null || { echo "frame 1 unreadable after redo"; exit 1; }
echo "render: chunks equal full runs; --skip-existing redoes only what is missing"
