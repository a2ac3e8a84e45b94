#!/bin/sh
# lint.stages: the direction between the engine's stages (stages.py), and the check itself: a warp
# unit planted with an include of the scene and of a blend header must fail it.
# usage: stages.sh SOURCE_DIR
set -u
src=$1
here=$(dirname "$0")
command -v python3 >/dev/null 2>&1 || { echo "python3 not installed: skipped"; exit 77; }
python3 "$here/stages.py" "$src" || exit 1
plant=$(mktemp -d)
trap 'rm -rf "$plant"' EXIT
printf '#include <volmorph/Scene.h>\n#include "blend/Sample.h"\n#include <vector>\n' >"$plant/planted.cpp"
if python3 "$here/stages.py" "$src" "$plant/planted.cpp:warp" >"$plant/out" 2>&1; then
    echo "lint.stages: a warp unit including the scene was not refused"; exit 1
fi
[ "$(grep -c 'planted.cpp (warp) includes' "$plant/out")" -eq 2 ] ||
    { echo "lint.stages: the planted includes were not both named:"; cat "$plant/out"; exit 1; }
echo "lint.stages: a planted backward include fails"
