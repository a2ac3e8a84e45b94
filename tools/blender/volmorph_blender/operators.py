# The add-on's operators: import a scene (pairs as empties, the sides' meshes, the morph as a
# Volume object), write the empties back into the scene's pairs, and make the morph again.
import os

import bpy
from bpy_extras.io_utils import ImportHelper

from . import placement
from .preferences import load_module

SIDES = ("source", "target")


def empty_name(index, side):
    return "pair{}.{}".format(index, side)


def settings(context):
    return context.scene.volmorph


def default_pattern(scene_path):
    """The morph's .vdb sequence beside the scene: out/blender/<scene>.####.vdb."""
    folder = os.path.dirname(os.path.abspath(scene_path))
    stem = os.path.splitext(os.path.basename(scene_path))[0]
    return os.path.join(folder, "out", "blender", stem + ".####.vdb")


def frame_file(pattern, frame):
    return pattern.replace("####", "%04d" % frame)


def link(obj, collection, root):
    collection.objects.link(obj)
    if root is not None:
        obj.parent = root
        obj.matrix_parent_inverse.identity()


def make_pair_empties(scene, collection, root):
    for index, pair in enumerate(scene.pairs, 1):
        shape, size = placement.DISPLAY[pair.type]
        for side in SIDES:
            obj = bpy.data.objects.new(empty_name(index, side), None)
            obj.empty_display_type = shape
            obj.empty_display_size = size
            obj["volmorph_pair"] = index
            obj["volmorph_side"] = side
            obj["volmorph_type"] = pair.type
            link(obj, collection, root)
            obj.matrix_basis = placement.side_matrix(getattr(pair, side))
            # what the file says, to tell a moved empty from float32 noise when writing back
            obj["volmorph_written"] = [v for row in obj.matrix_basis for v in row]


def make_side_meshes(scene, collection, root):
    """The source and target meshes as placed by the scene, drawn as wire, not rendered."""
    import numpy
    for side, mesh in scene.side_meshes().items():
        if mesh is None:
            continue  # a volume side
        points, triangles = mesh
        data = bpy.data.meshes.new(side + ".mesh")
        data.vertices.add(len(points))
        data.vertices.foreach_set("co", points.ravel())
        data.loops.add(3 * len(triangles))
        data.loops.foreach_set("vertex_index", triangles.astype(numpy.int32).ravel())
        data.polygons.add(len(triangles))
        data.polygons.foreach_set("loop_start", numpy.arange(0, 3 * len(triangles), 3,
                                                             dtype=numpy.int32))
        data.polygons.foreach_set("loop_total", numpy.full(len(triangles), 3, dtype=numpy.int32))
        data.update()
        obj = bpy.data.objects.new(side + ".mesh", data)
        obj.display_type = "WIRE"
        obj.hide_render = True
        link(obj, collection, root)


def write_sequence(scene, pattern):
    """Every frame's in-between through the module, with Blender's grid names. Returns the voxel
    size and the fastest voxel's speed (world units per second)."""
    wm = bpy.context.window_manager
    frames = scene.frames
    wm.progress_begin(0, len(frames))
    voxel = speed = 0.0
    try:
        for i, frame in enumerate(frames):
            grids = scene.morph(frame, path=frame_file(pattern, frame), names="blender")
            voxel = grids["density"].transform.voxelSize()[0]
            if "velocity" in grids:
                speed = max([speed] + [sum(c * c for c in v) ** 0.5
                                       for v in grids["velocity"].evalMinMax()])
            wm.progress_update(i + 1)
    finally:
        wm.progress_end()
    return voxel, speed


# Cycles pads a moving volume's bounds by its fastest voxel's travel over the shutter, everywhere:
# past this many voxels the padding takes minutes and gigabytes (a surface appearing in sdf mode
# moves fast for a frame), so the velocity grid is left for the user to set.
MAX_BLUR_PADDING_VOXELS = 48


def blur_padding_voxels(speed, voxel, context):
    """The voxels Cycles would pad by at the render's fps and shutter (frames)."""
    render = context.scene.render
    return speed * render.motion_blur_shutter / (render.fps / render.fps_base) / max(voxel, 1e-12)


def volume_material(scene, has_color):
    """Principled Volume as volmorph renders it: Density the extinction per world unit times the
    density grid, Color the albedo (times the color grid), no absorption colour."""
    medium = scene.medium
    mat = bpy.data.materials.new("volmorph.medium")
    mat.use_nodes = True
    mat.cycles.volume_interpolation = "LINEAR"
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    pv = nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Density"].default_value = medium["extinction"]
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    pv.inputs["Anisotropy"].default_value = medium["anisotropy"]
    a = medium["albedo"]
    if has_color:
        attr = nodes.new("ShaderNodeAttribute")
        attr.attribute_name = "color"
        mix = nodes.new("ShaderNodeMixRGB")
        mix.blend_type = "MULTIPLY"
        mix.inputs["Fac"].default_value = 1.0
        mix.inputs["Color2"].default_value = (a, a, a, 1.0)
        links.new(attr.outputs["Color"], mix.inputs["Color1"])
        links.new(mix.outputs["Color"], pv.inputs["Color"])
    else:
        pv.inputs["Color"].default_value = (a, a, a, 1.0)
    links.new(pv.outputs["Volume"], out.inputs["Volume"])
    return mat


def make_volume(scene, pattern, voxel, collection, root, name, velocity=True):
    """A Volume object whose frames are the sequence: scene frame f shows file f; blurred along
    its velocity grid (world units per second) when the render has motion blur on and
    `velocity`."""
    frames = scene.frames
    data = bpy.data.volumes.new(name)
    data.filepath = frame_file(pattern, frames[0])
    data.is_sequence = True
    data.frame_start = frames[0]
    data.frame_duration = len(frames)
    data.frame_offset = frames[0] - 1  # Blender's file frame: f - start + 1 + offset
    data.sequence_mode = "CLIP"
    data.grids.load()
    names = {g.name for g in data.grids}
    if velocity and "velocity" in names:  # a single frame has none (t stands still)
        data.velocity_grid = "velocity"
        data.velocity_unit = "SECOND"
        data.velocity_scale = 1.0
    has_color = "color" in names
    data.materials.append(volume_material(scene, has_color))
    obj = bpy.data.objects.new(name, data)
    link(obj, collection, root)
    # Blender puts voxel (i, j, k) at (i + 0.5) voxels; OpenVDB (and volmorph) at i.
    obj.location = (-0.5 * voxel,) * 3
    return obj


def pairs_from_empties(scene, objects):
    """The scene's pairs with each moved empty's transform in its side; the others as read."""
    pairs = scene.pairs
    moved = 0
    for obj in objects:
        index, side = obj.get("volmorph_pair"), obj.get("volmorph_side")
        if index is None or side not in SIDES or not 1 <= index <= len(pairs):
            continue
        root = obj.parent
        local = (root.matrix_world.inverted() @ obj.matrix_world) if root else obj.matrix_world
        written = obj.get("volmorph_written")
        if written is not None:
            was = [list(written[4 * i:4 * i + 4]) for i in range(4)]
            if not placement.moved(local, was):
                continue
        setattr(pairs[index - 1], side, placement.side_from_matrix(local))
        moved += 1
    return pairs, moved


def collection_objects(context):
    coll = bpy.data.collections.get(settings(context).collection)
    return list(coll.all_objects) if coll else []


class VOLMORPH_OT_import_scene(bpy.types.Operator, ImportHelper):
    """Import a volmorph scene: its feature pairs as empties, its meshes, its morph as a volume"""
    bl_idname = "volmorph.import_scene"
    bl_label = "Import volmorph scene"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".toml"
    filter_glob: bpy.props.StringProperty(default="*.toml", options={"HIDDEN"})

    def execute(self, context):
        try:
            vm = load_module()
            scene = vm.Scene(self.filepath)
            stem = os.path.splitext(os.path.basename(self.filepath))[0]
            collection = bpy.data.collections.new("volmorph " + stem)
            context.scene.collection.children.link(collection)
            root = bpy.data.objects.new(stem, None)
            root.empty_display_type = "ARROWS"
            root.empty_display_size = 0.2
            root.rotation_euler = placement.ROOT_ROTATION
            link(root, collection, None)
            make_pair_empties(scene, collection, root)
            make_side_meshes(scene, collection, root)
            pattern = default_pattern(self.filepath)
            context.scene.render.fps = max(1, round(scene.medium["fps"]))
            context.scene.render.fps_base = 1.0
            voxel, speed = write_sequence(scene, pattern)
            padding = blur_padding_voxels(speed, voxel, context)
            blur = padding <= MAX_BLUR_PADDING_VOXELS
            make_volume(scene, pattern, voxel, collection, root, stem + ".morph", blur)
        except (ImportError, ValueError, OSError, RuntimeError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        s = settings(context)
        s.filepath, s.vdb_pattern, s.collection = self.filepath, pattern, collection.name
        s.frame_first, s.frame_last = scene.frames[0], scene.frames[-1]
        context.scene.frame_start, context.scene.frame_end = s.frame_first, s.frame_last
        self.report({"INFO"}, "volmorph: {} pairs, {} frames".format(len(scene.pairs),
                                                                      len(scene.frames)))
        if not blur:
            self.report({"WARNING"},
                        "volmorph: the morph's fastest voxel moves {:.0f} voxels over the shutter; "
                        "Cycles would pad the whole volume by that, so its velocity grid is not "
                        "set (set it in the volume's properties, with a velocity scale, for "
                        "motion blur)".format(padding))
        return {"FINISHED"}


class VOLMORPH_OT_write_pairs(bpy.types.Operator):
    """Write the empties' transforms into the scene's pairs (every other byte of the file kept)"""
    bl_idname = "volmorph.write_pairs"
    bl_label = "Write pairs"
    bl_options = {"REGISTER"}
    filepath: bpy.props.StringProperty(subtype="FILE_PATH", default="",
                                       description="Where to write (default: the scene itself)")

    @classmethod
    def poll(cls, context):
        return bool(settings(context).filepath)

    def execute(self, context):
        try:
            scene = load_module().Scene(settings(context).filepath)
            objects = collection_objects(context)
            pairs, moved = pairs_from_empties(scene, objects)
            scene.pairs = pairs
            scene.save(self.filepath or None)
        except (ImportError, ValueError, OSError, RuntimeError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        for obj in objects:  # what the file says now
            if obj.get("volmorph_side") in SIDES:
                obj["volmorph_written"] = [v for row in obj.matrix_basis for v in row]
        self.report({"INFO"}, "volmorph: {} pair sides written".format(moved))
        return {"FINISHED"}


class VOLMORPH_OT_remorph(bpy.types.Operator):
    """Make the morph's volumes again, with the pairs as the empties place them (unsaved edits
    too)"""
    bl_idname = "volmorph.remorph"
    bl_label = "Morph again"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return bool(settings(context).filepath)

    def execute(self, context):
        s = settings(context)
        try:
            scene = load_module().Scene(s.filepath)
            objects = collection_objects(context)
            scene.pairs, _ = pairs_from_empties(scene, objects)
            write_sequence(scene, s.vdb_pattern)  # the volume's velocity setting is the user's
        except (ImportError, ValueError, OSError, RuntimeError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        for obj in objects:
            if obj.type == "VOLUME":
                obj.data.filepath = obj.data.filepath  # reloads the sequence
        return {"FINISHED"}


def menu_import(self, context):
    self.layout.operator(VOLMORPH_OT_import_scene.bl_idname, text="volmorph scene (.toml)")


CLASSES = (VOLMORPH_OT_import_scene, VOLMORPH_OT_write_pairs, VOLMORPH_OT_remorph)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
