# Where the add-on finds the `volmorph` module, and the scene properties the panel shows.
import os
import sys

import bpy

ADDON = __package__


class VolmorphPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON

    module_path: bpy.props.StringProperty(
        name="volmorph module folder",
        description="The folder that holds the volmorph Python package (a build's python/ "
                    "folder); empty when it is installed on Python's path",
        subtype="DIR_PATH", default="")

    def draw(self, context):
        self.layout.prop(self, "module_path")


def load_module():
    """The `volmorph` module: from Python's path, the add-on's preference, or the environment's
    VOLMORPH_PYTHONPATH (Blender ignores PYTHONPATH). Raises ImportError saying where it looked."""
    try:
        import volmorph
        return volmorph
    except ImportError:
        pass
    prefs = bpy.context.preferences.addons.get(ADDON)
    folders = [bpy.path.abspath(prefs.preferences.module_path)] if prefs else []
    folders += os.environ.get("VOLMORPH_PYTHONPATH", "").split(os.pathsep)
    for folder in filter(None, folders):
        if os.path.isdir(os.path.join(folder, "volmorph")) and folder not in sys.path:
            sys.path.append(folder)
    try:
        import volmorph
        return volmorph
    except ImportError as error:
        raise ImportError("the volmorph Python module was not found (set its folder in the "
                          "add-on's preferences, e.g. build/python): " + str(error)) from error


class VolmorphSceneSettings(bpy.types.PropertyGroup):
    filepath: bpy.props.StringProperty(name="Scene", subtype="FILE_PATH",
                                       description="The volmorph scene file (TOML)")
    vdb_pattern: bpy.props.StringProperty(
        name="Volumes", subtype="FILE_PATH",
        description="Where the morph's .vdb sequence is written (#### is the frame)")
    frame_first: bpy.props.IntProperty(name="First")
    frame_last: bpy.props.IntProperty(name="Last")
    collection: bpy.props.StringProperty(name="Collection")


def register():
    bpy.utils.register_class(VolmorphPreferences)
    bpy.utils.register_class(VolmorphSceneSettings)
    bpy.types.Scene.volmorph = bpy.props.PointerProperty(type=VolmorphSceneSettings)


def unregister():
    del bpy.types.Scene.volmorph
    bpy.utils.unregister_class(VolmorphSceneSettings)
    bpy.utils.unregister_class(VolmorphPreferences)
