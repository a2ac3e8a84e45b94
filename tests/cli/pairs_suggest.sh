#!/bin/sh
# volmorph pairs suggest: the new [[pair]] tables on stdout (the scene untouched); with -o a new file
# holding the scene byte for byte with them after its own pairs, which volmorph check accepts; -o onto
# the scene itself refused.
# usage: pairs_suggest.sh VOLMORPH SOURCE_DIR
set -eu
volmorph=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VOLMORPH_CACHE="$out/cache"
sed "s|\"meshes/|\"$2/scenes/meshes/|" "$2/scenes/sphere-to-box.toml" >"$out/scene.toml"
cp "$out/scene.toml" "$out/before.toml"

"$volmorph" pairs suggest "$out/scene.toml" >"$out/printed.toml"
cmp -s "$out/scene.toml" "$out/before.toml" || { echo "pairs suggest without -o changed the scene"; exit 1; }
grep -q '^# suggested by volmorph pairs suggest$' "$out/printed.toml" || { echo "no comment"; cat "$out/printed.toml"; exit 1; }
grep -q '^type = "box"$' "$out/printed.toml" || { echo "no box pair"; cat "$out/printed.toml"; exit 1; }
! grep -q "voxelized" "$out/printed.toml" || { echo "progress mixed into the pairs"; exit 1; }

"$volmorph" pairs suggest "$out/scene.toml" -o "$out/suggested.toml" -q
# Every line of the scene is there, in order, and the suggested pairs come after its own.
awk 'NR == FNR { want[++n] = $0; next } i < n && $0 == want[i + 1] { ++i } END { exit i != n }' \
    "$out/scene.toml" "$out/suggested.toml" || { echo "the scene's own lines were not kept"; exit 1; }
[ "$(grep -c '^\[\[pair\]\]' "$out/suggested.toml")" -gt 1 ] || { echo "no pair appended"; exit 1; }
"$volmorph" check "$out/suggested.toml" >/dev/null || { echo "check refuses the result"; exit 1; }

set +e
"$volmorph" pairs suggest "$out/scene.toml" -o "$out/scene.toml" 2>"$out/err"
code=$?
set -e
[ $code -eq 1 ] || { echo "-o onto the scene: exit $code"; exit 1; }
grep -q "never edits a scene in place" "$out/err" || { cat "$out/err"; exit 1; }
cmp -s "$out/scene.toml" "$out/before.toml" || { echo "the scene was edited in place"; exit 1; }
echo "pairs suggest: printed, appended to a new file with the scene kept, never in place"
