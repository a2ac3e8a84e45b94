#!/bin/sh
# volmorph preview: a frame with its features, a contact sheet from rendered EXRs or rendered on the
# fly, and clear errors for frames out of range or missing.
# usage: preview.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
scene=$2/scenes/sphere-to-box.toml
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
size() { oiiotool --info "$1" | sed -n 's/.* : *\([0-9]*\) x *\([0-9]*\),.*/\1x\2/p'; }

"$volmorph" preview "$scene" --frame 2 --sides -o "$dir/p.png" -q
"$volmorph" preview "$scene" --frame 2 --no-features -o "$dir/plain.png" -q
[ "$(size "$dir/p.png")" = 256x128 ] || { echo "preview size $(size "$dir/p.png")"; exit 1; }
set +e
"$volmorph" diff -q "$dir/plain.png" "$dir/p.png" 2>/dev/null; status=$?
set -e
[ $status = 2 ] || { echo "the features changed nothing (diff status $status)"; exit 1; }

"$volmorph" render "$scene" -o "$dir/f.####.exr" -q
"$volmorph" preview "$scene" --contact-sheet --from "$dir/f.####.exr" --columns 3 --tile-width 100 -o "$dir/sheet.png" -q
[ "$(size "$dir/sheet.png")" = 324x162 ] || { echo "contact sheet size $(size "$dir/sheet.png")"; exit 1; }
"$volmorph" preview "$scene" --contact-sheet --frames 0-4x2 --features --tile-width 100 -o "$dir/live.png" -q
[ "$(size "$dir/live.png")" = 324x84 ] || { echo "live contact sheet size $(size "$dir/live.png")"; exit 1; }

expect_error() { # exit status, stderr fragment, command...
    want=$1 text=$2; shift 2
    set +e
    "$@" >/dev/null 2>"$dir/err"; got=$?
    set -e
    [ $got = "$want" ] && grep -q "$text" "$dir/err" || { echo "$*: status $got, stderr:"; cat "$dir/err"; exit 1; }
}
rm "$dir/f.0003.exr"
expect_error 1 "f.0003.exr: cannot read frame 3" \
    "$volmorph" preview "$scene" --contact-sheet --from "$dir/f.####.exr" -o "$dir/x.png"
expect_error 1 "outside the scene's range" "$volmorph" preview "$scene" --frame 99 -o "$dir/x.png"
expect_error 1 "either --frame N or --contact-sheet" "$volmorph" preview "$scene" -o "$dir/x.png"
[ ! -e "$dir/x.png" ] || { echo "a failed preview left $dir/x.png"; exit 1; }
echo "preview: features drawn, contact sheets from EXRs and live, errors named"
