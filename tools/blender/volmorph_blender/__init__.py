# volmorph for Blender: a scene's feature pairs as empties in the viewport, written back to the
# scene file, and the morph on the timeline as a Volume object (density, color, velocity) that
# Cycles renders with motion blur. The work is the `volmorph` Python module's (tools/python);
# this add-on only places its results in Blender.
#
# Install: Edit > Preferences > Add-ons > Install..., pick a zip of this folder (or link the folder
# into Blender's scripts/addons), enable "volmorph"; tell it where the module is in the add-on's
# preferences (the build's python/ folder) unless `cmake --install` put it on Python's path.

bl_info = {
    "name": "volmorph",
    "author": "volmorph developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > Sidebar (N) > volmorph",
    "description": "Feature-based volume morphing: edit a scene's feature pairs as empties and "
                   "put its morph on the timeline as a volume",
    "category": "Import-Export",
}

from . import operators, panel, preferences  # noqa: E402

_modules = (preferences, operators, panel)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
