#!/bin/sh
# The Blender add-on (tools/blender/volmorph_blender) in headless Blender 3.4: installed as a user
# add-on, enabled, then blender_addon_test.py drives it. Skips (77) where Blender is absent.
# usage: blender_addon.sh VOLMORPH SOURCE_DIR PYTHON_DIR
set -eu
volmorph=$1 source=$2 python=$3
if ! command -v blender >/dev/null 2>&1; then
    echo "skipped: no blender on this machine (apt-get install blender)"
    exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/scripts/addons"
ln -s "$source/tools/blender/volmorph_blender" "$tmp/scripts/addons/volmorph_blender"
BLENDER_USER_SCRIPTS=$tmp/scripts BLENDER_USER_CONFIG=$tmp/config VOLMORPH_PYTHONPATH=$python \
VOLMORPH=$volmorph VOLMORPH_SOURCE_DIR=$source VOLMORPH_TMP=$tmp \
    blender -b --factory-startup --python-exit-code 1 \
            --python "$source/tests/python/blender_addon_test.py"
