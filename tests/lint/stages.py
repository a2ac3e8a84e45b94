#!/usr/bin/env python3
"""The direction between the engine's stages (ARCHITECTURE.md): a stage includes only the stages before
it on the data-flow line, never one after it. render/ and the core library are checked by
tests/cli/layering.sh; this checks libvolmorph's stages among themselves, by their includes.

usage: stages.py SOURCE_DIR [EXTRA_FILE:STAGE ...]
Each file of libvolmorph/src/<stage>/ and each public header belongs to a stage; every
`#include <volmorph/X.h>` and `#include "stage/X.h"` it has must name a stage it may read. An
EXTRA_FILE is checked as if it belonged to STAGE (the test that plants a wrong include).
"""
import re
import sys
from pathlib import Path

# The public headers' stages (libvolmorph/include/volmorph/); core/ is the core library's.
HEADERS = {
    "Mesh.h": "mesh", "Voxelize.h": "voxelize", "VolumeSet.h": "volumeset",
    "VolumeSource.h": "volume", "VolumeInput.h": "volume",
    "FeaturePair.h": "feature", "Feature.h": "feature", "PairSuggest.h": "feature",
    "WarpSettings.h": "warp", "Warp.h": "warp",
    "Schedule.h": "blend", "BlendSettings.h": "blend",
    "Morph.h": "morph", "Export.h": "export",
    "Scene.h": "scene", "Frames.h": "scene", "SceneDocument.h": "scene",
    "SceneVolumes.h": "sides", "VoxelCache.h": "sides", "SceneSurface.h": "sides",
    "SurfaceSettings.h": "surface", "SurfaceMorph.h": "surface",
    "TimingSettings.h": "timing", "LocalTime.h": "timing",
}

# What each stage may read, itself included. The scene builds every stage's options, so it reads
# their settings headers; `sides` is the adapter from a Scene to the stages that make volumes.
ALLOWED = {
    "core": {"core"},
    "volumeset": {"core", "volumeset"},
    "mesh": {"core", "mesh"},
    "voxelize": {"core", "volumeset", "mesh", "voxelize"},
    "volume": {"core", "volumeset", "voxelize", "volume"},
    "feature": {"core", "volumeset", "feature"},
    "timing": {"core", "timing"},
    "warp": {"core", "volumeset", "feature", "timing", "warp"},
    "blend": {"core", "volumeset", "voxelize", "feature", "timing", "warp", "blend"},
    "morph": {"core", "volumeset", "voxelize", "feature", "timing", "warp", "blend", "morph"},
    "surface": {"core", "mesh", "timing", "surface"},
    "export": {"core", "volumeset", "mesh", "surface", "export"},
    "scene": {"core", "feature", "timing", "warp", "blend", "volume", "surface", "scene"},
    "sides": {"core", "volumeset", "mesh", "voxelize", "volume", "export", "feature", "timing",
              "blend", "surface", "scene", "sides"},
}

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', re.M)


def stage_of_include(name, here):
    if name.startswith("volmorph/core/"): return "core"
    if name.startswith("volmorph/"): return HEADERS.get(name[len("volmorph/"):], "unknown:" + name)
    first = name.split("/")[0]
    if first in ALLOWED: return first
    if "/" not in name and name.endswith(".h"): return here  # a header beside its source
    return None  # a system or third-party header


def files(root):
    for p in sorted((root / "libvolmorph" / "src").rglob("*")):
        if p.suffix in (".h", ".cpp"):
            yield p, p.relative_to(root / "libvolmorph" / "src").parts[0]
    for p in sorted((root / "libvolmorph" / "include" / "volmorph").glob("*.h")):
        yield p, HEADERS.get(p.name, "unknown:" + p.name)
    for p in sorted((root / "libvolmorph" / "include" / "volmorph" / "core").glob("*.h")):
        yield p, "core"


def check(items):
    problems = []
    for path, stage in items:
        if stage not in ALLOWED:
            problems.append("%s: no stage is known for it (add it to tests/lint/stages.py)" % path)
            continue
        for name in INCLUDE.findall(path.read_text(errors="replace")):
            other = stage_of_include(name, stage)
            if other is None or other in ALLOWED[stage]: continue
            problems.append("%s (%s) includes %s (%s)" % (path, stage, name, other))
    return problems


def main(argv):
    if len(argv) < 2:
        print("usage: stages.py SOURCE_DIR [EXTRA_FILE:STAGE ...]", file=sys.stderr)
        return 2
    root = Path(argv[1])
    items = list(files(root)) + [(Path(a.rsplit(":", 1)[0]), a.rsplit(":", 1)[1]) for a in argv[2:]]
    problems = check(items)
    if problems:
        print("a stage includes one it may not read (ARCHITECTURE.md, the data flow):")
        for p in problems: print("  " + p)
        return 1
    print("stages: every include reads an earlier stage (%d files)" % len(items))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
