#!/bin/sh
# The editor's page in headless chromium (issue 39): on a copy of the default scene, open the page,
# take a screenshot of it loaded (compared with tests/browser/editor.png under thresholds: SwiftShader
# renders the same page alike, not bit for bit), select pair 2, drag its target origin with the
# gizmo, save. The saved file must differ from the original on that one line alone (every comment
# and every other byte kept). Then a surface-mode scene, and a scene with a timing sweep (its delay's
# colours, its end dragged). Screenshots are left in OUT (default: ./browser-out).
# usage: editor.sh VOLMORPH SOURCE_DIR [OUT]
set -eu
. "$(dirname "$0")/../cli/lib.sh"
shots=${3:-$PWD/browser-out}
mkdir -p "$shots"
[ -x /usr/bin/chromium ] || { echo "chromium is missing (tools/install-deps.sh installs it)"; exit 1; }
[ -d "$src/tools/editor/web/node_modules/playwright-core" ] ||
    { echo "playwright-core is missing (tools/install-deps.sh runs npm ci)"; exit 1; }
default_scene "$out/scene.toml"
cp "$out/scene.toml" "$out/original.toml"
start_editor "$out/scene.toml" --resolution 64 -q
node "$src/tests/browser/editor_test.mjs" "$url" "$shots" || { stop_editor 10; exit 1; }
stop_editor 10

# One line changed: pair 2's target, which holds the dragged origin.
diff "$out/original.toml" "$out/scene.toml" >"$out/diff" && { echo "the scene was not saved"; exit 1; }
[ "$(grep -c '^[<>]' "$out/diff")" = 2 ] || { echo "more than one line changed:"; cat "$out/diff"; exit 1; }
grep -q '^< target = { origin = \[-0.45, 0.40, 0.0\] }$' "$out/diff" ||
    { echo "the changed line is not pair 2's target:"; cat "$out/diff"; exit 1; }
grep -q '^> target = { origin = \[' "$out/diff" || { cat "$out/diff"; exit 1; }
"$volmorph" check "$out/scene.toml" >/dev/null

# The loaded page against the reference: at most 0.5% of the pixels more than 0.1 apart (repeated
# runs here gave identical screenshots; widening the type selector alone changed 0.02% of them).
"$volmorph" diff "$shots/editor.png" "$src/tests/browser/editor.png" --fail 0.1 --failpercent 0.5 \
    --warn 0.1 --warnpercent 0.5 -o "$shots/editor.diff.png" || { echo "the page looks different: $shots/editor.diff.png"; exit 1; }
# A surface-mode scene: landmarks only, snapped to the target, the in-between made again.
sed "s|\"meshes/|\"$src/scenes/meshes/|; s|\"skies/|\"$src/scenes/skies/|" \
    "$src/scenes/blobby-to-star-surface.toml" >"$out/surface.toml"
start_editor "$out/surface.toml" -q
node "$src/tests/browser/editor_surface.mjs" "$url" "$shots" || { stop_editor 10; exit 1; }
stop_editor 10
# A scene with a sweep: the in-between coloured by its delays, the sweep's end dragged and saved;
# the sweep's line alone changed, and the file still a valid scene.
sed "s|\"meshes/|\"$src/scenes/meshes/|; s|\"skies/|\"$src/scenes/skies/|" \
    "$src/scenes/bunny-to-knot-sweep.toml" >"$out/sweep.toml"
cp "$out/sweep.toml" "$out/sweep.original.toml"
start_editor "$out/sweep.toml" --resolution 64 -q
node "$src/tests/browser/editor_timing.mjs" "$url" "$shots" || { stop_editor 10; exit 1; }
stop_editor 10
diff "$out/sweep.original.toml" "$out/sweep.toml" >"$out/sweep.diff" && { echo "the sweep scene was not saved"; exit 1; }
[ "$(grep -c '^[<>]' "$out/sweep.diff")" = 2 ] || { echo "more than the sweep's line changed:"; cat "$out/sweep.diff"; exit 1; }
grep -q '^> sweep = { origin = \[0, 0, 0\], direction = \[' "$out/sweep.diff" ||
    { echo "the changed line is not the sweep's:"; cat "$out/sweep.diff"; exit 1; }
"$volmorph" check "$out/sweep.toml" >/dev/null
echo "editor page: dragged pair 2's target origin and saved; one line changed; screenshot within bounds; a surface scene's landmark snapped; a sweep's end dragged and saved"
