#!/bin/sh
# A render killed with SIGKILL in the middle of a frame leaves no file at a final name that does
# not read back whole; rerun with --skip-existing, it gives the same frames, pixel for pixel, as an
# uninterrupted run.
# usage: render_sigkill.sh VOLMORPH SOURCE_DIR [COARSEN]
#        COARSEN: frames 1024x512 divided by this (default 1; 2 for sanitizer builds, which run 5-40
#        times slower), so that a frame lasts about a second
set -eu
volmorph=$1
coarsen=${3:-1}
dir=$(mktemp -d)
trap 'kill -9 $pid 2>/dev/null || true; rm -rf "$dir"' EXIT
pid=0
# The analytic scene, with frames large enough (about a second each) to be killed inside one.
sed "s|meshes/|$2/scenes/meshes/|; s|resolution = \[256, 128\]|resolution = [$((1024 / coarsen)), $((512 / coarsen))]|" \
    "$2/scenes/sphere-to-box.toml" >"$dir/scene.toml"
export VOLMORPH_CACHE="$dir/cache"

"$volmorph" render "$dir/scene.toml" -o "$dir/whole/f.####.exr" -q

"$volmorph" render "$dir/scene.toml" -o "$dir/killed/f.####.exr" >"$dir/log" 2>&1 &
pid=$!
# Wait until frame 1 is written, then kill while frame 2 is being made.
i=0
until grep -q "^frame 1 " "$dir/log" 2>/dev/null; do
    i=$((i + 1)); [ $i -lt 600 ] || { echo "frame 1 never finished"; cat "$dir/log"; exit 1; }
    sleep 0.1
done
sleep 0.3
kill -9 $pid
wait $pid 2>/dev/null || true
grep -q "^frame 4 " "$dir/log" && { echo "the run finished before it was killed; nothing tested"; exit 1; }

for f in "$dir"/killed/f.[0-9][0-9][0-9][0-9].exr; do # every file at a final name reads back whole and is right
    "$volmorph" diff -q --fail 0 "$dir/whole/$(basename "$f")" "$f" || { echo "$f is partial or wrong"; exit 1; }
done
before=$(ls "$dir/killed" | grep -c '^f\.[0-9]*\.exr$' || true)

"$volmorph" render "$dir/scene.toml" -o "$dir/killed/f.####.exr" --skip-existing >"$dir/log2"
skipped=$(grep -c "exists, skipped" "$dir/log2" || true)
[ "$skipped" = "$before" ] || { echo "skipped $skipped frames, $before were complete"; cat "$dir/log2"; exit 1; }
for n in 0000 0001 0002 0003 0004; do
    "$volmorph" diff -q --fail 0 "$dir/whole/f.$n.exr" "$dir/killed/f.$n.exr" || { echo "frame $n differs"; exit 1; }
done
echo "SIGKILL after $before complete frames; rerun with --skip-existing equals an uninterrupted run"
