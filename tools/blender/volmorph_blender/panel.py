# The add-on's panel in the 3D viewport's sidebar (N): the scene's path, its frames, the operators.
import bpy


class VOLMORPH_PT_scene(bpy.types.Panel):
    bl_label = "volmorph"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "volmorph"

    def draw(self, context):
        layout = self.layout
        s = context.scene.volmorph
        layout.operator("volmorph.import_scene", icon="IMPORT")
        if not s.filepath:
            layout.label(text="Import a scene (.toml) to begin")
            return
        layout.prop(s, "filepath")
        layout.prop(s, "vdb_pattern")
        row = layout.row()
        row.enabled = False  # the scene's [frames] say them
        row.prop(s, "frame_first")
        row.prop(s, "frame_last")
        layout.operator("volmorph.write_pairs", icon="FILE_TICK")
        layout.operator("volmorph.remorph", icon="FILE_REFRESH")


def register():
    bpy.utils.register_class(VOLMORPH_PT_scene)


def unregister():
    bpy.utils.unregister_class(VOLMORPH_PT_scene)
