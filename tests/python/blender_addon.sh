#!/bin/sh
# The Blender add-on (tools/blender/volmorph_blender) in headless Blender 3.4: installed from the
# build's zip as a user installs it, enabled, then blender_addon_test.py drives it. Skips (77) where
# Blender is absent.
# usage: blender_addon.sh VOLMORPH SOURCE_DIR PYTHON_DIR ADDON_ZIP
set -eu
volmorph=$1 source=$2 python=$3 zip=$4
if ! command -v blender >/dev/null 2>&1; then
    echo "skipped: no blender on this machine (apt-get install blender)"
    exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/scripts/addons"
BLENDER_USER_SCRIPTS=$tmp/scripts BLENDER_USER_CONFIG=$tmp/config VOLMORPH_PYTHONPATH=$python \
VOLMORPH=$volmorph VOLMORPH_SOURCE_DIR=$source VOLMORPH_TMP=$tmp VOLMORPH_ADDON_ZIP=$zip \
    blender -b --factory-startup --python-exit-code 1 \
            --python "$source/tests/python/blender_addon_test.py"
