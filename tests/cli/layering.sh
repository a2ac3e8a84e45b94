#!/bin/sh
# The layering the architecture promises (ARCHITECTURE.md): the core library includes only itself,
# and render/ includes only the core library and itself, never the engine's stages.
# usage: layering.sh SOURCE_DIR
set -eu
cd "$1"
status=0
bad=$(grep -rn '#include <volmorph/' libvolmorph/src/core libvolmorph/include/volmorph/core | grep -v '<volmorph/core/' || true)
if [ -n "$bad" ]; then echo "core reaches outside itself:"; echo "$bad"; status=1; fi
bad=$(grep -rn '#include <volmorph/' render | grep -v '<volmorph/core/' | grep -v '<volmorph/render/' || true)
if [ -n "$bad" ]; then echo "render/ includes the engine:"; echo "$bad"; status=1; fi
bad=$(grep -rn '#include "' render | grep -v '#include "[A-Za-z]*\.h"' || true)
if [ -n "$bad" ]; then echo "render/ includes a private header from elsewhere:"; echo "$bad"; status=1; fi
[ "$status" -eq 0 ] && echo "layering: core and render/ include nothing of the engine"
exit "$status"
