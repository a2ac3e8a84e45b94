#!/bin/sh
# The README's "Your first morph", command for command as a new user would type them: the ```sh blocks
# between its heading and the next, run in order by one shell in an empty folder that has the
# checkout's scenes/ and this build's bin/ where the README says they are. Then what the text promises:
# the paired scene, the preview, three frames with their layers, the contact sheet, the layer taken out.
# usage: first_morph.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
awk '/^## Your first morph/ { on = 1; next } on && /^## / { exit }
     on && /^```sh$/ { code = 1; next } code && /^```$/ { code = 0; next } code { print }' \
    "$src/README.md" >"$work/walkthrough.sh"
[ "$(grep -c '^volmorph ' "$work/walkthrough.sh")" -ge 5 ] ||
    { echo "the walk-through has fewer commands than expected:"; cat "$work/walkthrough.sh"; exit 1; }
mkdir -p "$work/build"
ln -s "$src/scenes" "$work/scenes"
ln -s "$(cd "$(dirname "$volmorph")" && pwd)" "$work/build/bin"
(cd "$work" && sh -eu walkthrough.sh) >"$work/log" 2>&1 || { echo "the walk-through failed:"; cat "$work/log"; exit 1; }
for f in first/paired.toml first/pairs.0012.png first/out/first.0001.exr first/out/first.0012.exr \
         first/out/first.0024.exr first/contact-sheet.png first/direct.0012.exr; do
    [ -s "$work/$f" ] || { echo "the walk-through did not write $f:"; cat "$work/log"; exit 1; }
done
grep -q '^\[\[pair\]\]' "$work/first/paired.toml" || { echo "no pairs suggested"; exit 1; }
for layer in volume.A direct.R indirect.R emission.R depth.Z; do
    grep -q "$layer" "$work/log" || { echo "iinfo did not list $layer:"; cat "$work/log"; exit 1; }
done
[ ! -e "$work/first/out/first.0002.exr" ] || { echo "--frames 1,12,24 rendered frame 2"; exit 1; }
echo "the README's first morph runs as written ($(grep -c '' "$work/walkthrough.sh") lines)"
