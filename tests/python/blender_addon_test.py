"""The add-on in headless Blender (run by blender_addon.sh): import a scene, find 2 x pairs empties
and the Volume, move an empty, write the pairs, `volmorph check` the written file, render one frame
with Cycles and motion blur, and find the volume in the image."""

import difflib
import os
import pathlib
import shutil
import subprocess
import sys

import addon_utils
import bpy
from mathutils import Vector

EXE = os.environ["VOLMORPH"]
SOURCE = pathlib.Path(os.environ["VOLMORPH_SOURCE_DIR"])
TMP = pathlib.Path(os.environ["VOLMORPH_TMP"])


def check(condition, what):
    if not condition:
        print("FAIL: " + what)
        sys.exit(1)
    print("ok: " + what)


# the scene, copied with its meshes and skies linked beside it
work = TMP / "shot"
work.mkdir()
for sub in ("meshes", "skies"):
    os.symlink(SOURCE / "scenes" / sub, work / sub)
scene_path = work / "sphere-to-box.toml"  # density mode: Cycles blurs it in seconds
shutil.copy(SOURCE / "scenes" / "sphere-to-box.toml", scene_path)
before = scene_path.read_text()

bpy.ops.wm.read_factory_settings(use_empty=True)  # no default cube in the shot
bpy.ops.preferences.addon_install(filepath=os.environ["VOLMORPH_ADDON_ZIP"])
addon_utils.enable("volmorph_blender", default_set=True, handle_error=None)
check("volmorph_blender" in bpy.context.preferences.addons, "the add-on is enabled")

result = bpy.ops.volmorph.import_scene(filepath=str(scene_path))
check(result == {"FINISHED"}, "import_scene finished")
import volmorph  # the add-on found it (VOLMORPH_PYTHONPATH)
pairs = volmorph.Scene(scene_path).pairs
names = ["pair{}.{}".format(i, side) for i in range(1, len(pairs) + 1)
         for side in ("source", "target")]
empties = [o for o in bpy.data.objects if o.type == "EMPTY" and o.name.startswith("pair")]
check(sorted(o.name for o in empties) == sorted(names),
      "2 x {} pair empties: {}".format(len(pairs), ", ".join(sorted(o.name for o in empties))))
check(bpy.data.objects["pair1.source"].empty_display_type == "CUBE", "a box pair draws as a cube")
check(bpy.data.objects["source.mesh"].type == "MESH", "the source mesh, for reference")
volumes = [o for o in bpy.data.objects if o.type == "VOLUME"]
check(len(volumes) == 1, "one Volume object")
volumes[0].data.grids.load()
grids = {g.name for g in volumes[0].data.grids}
print("volume file:", volumes[0].data.grids.frame_filepath, volumes[0].data.grids.error_message)
check({"density", "color", "velocity"} <= grids, "its grids: " + ", ".join(sorted(grids)))
frames = volmorph.Scene(scene_path).frames
check(volumes[0].data.is_sequence and volumes[0].data.frame_duration == len(frames),
      "a {}-frame sequence".format(len(frames)))
check(volumes[0].data.velocity_grid == "velocity", "blurred along its velocity grid")

# move pair 1's target 0.1 along the scene's x
moved = bpy.data.objects["pair1.target"]
was = Vector(pairs[0].target["origin"])
moved.matrix_basis.translation.x += 0.1
check(bpy.ops.volmorph.write_pairs() == {"FINISHED"}, "write_pairs finished")
after = scene_path.read_text()
changed = [l for l in difflib.ndiff(before.splitlines(), after.splitlines()) if l[:1] in "+-"]
check(len(changed) == 2, "one line of the file changed: " + " | ".join(changed))
now = volmorph.Scene(scene_path).pairs[0].target["origin"]
check(abs(now[0] - was.x - 0.1) < 1e-6 and abs(now[1] - was.y) < 1e-6,
      "pair 1's target moved 0.1 along x: {} -> {}".format(tuple(was), now))
checked = subprocess.run([EXE, "check", str(scene_path)], capture_output=True, text=True)
check(checked.returncode == 0, "volmorph check accepts the written scene " + checked.stderr)

check(hasattr(bpy.types, "VOLMORPH_PT_scene"), "the sidebar panel is registered")
first = pathlib.Path(volumes[0].data.filepath)
stamp = first.stat().st_mtime_ns
check(bpy.ops.volmorph.remorph() == {"FINISHED"} and first.stat().st_mtime_ns > stamp,
      "remorph writes the sequence again")

# render the middle frame with Cycles, motion blur on, from a camera framing the volume
scene = bpy.context.scene
scene.frame_set(frames[len(frames) // 2])
vol = volumes[0]
corners = [vol.matrix_world @ Vector(c) for c in vol.bound_box]
centre = sum(corners, Vector()) / 8.0
extent = max((c - centre).length for c in corners)
print("volume bounds", tuple(corners[0]), tuple(corners[6]), "centre", tuple(centre))
cam_data = bpy.data.cameras.new("cam")
cam = bpy.data.objects.new("cam", cam_data)
scene.collection.objects.link(cam)
cam.location = centre + Vector((0.0, -4.0 * extent, 0.0))
cam.rotation_euler = (centre - cam.location).to_track_quat("-Z", "Y").to_euler()
scene.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
scene.collection.objects.link(sun)
scene.render.engine = "CYCLES"
scene.cycles.samples = 8
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
scene.cycles.device = "CPU"
scene.render.resolution_x, scene.render.resolution_y = 96, 64
scene.render.film_transparent = True
scene.render.use_motion_blur = True
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.filepath = str(TMP / "frame.exr")
bpy.ops.render.render(write_still=True)
image = bpy.data.images.load(str(TMP / "frame.exr"))
alpha = list(image.pixels)[3::4]
w, h = image.size
centre_alpha = alpha[(h // 2) * w + w // 2]
check(max(alpha) > 0.5 and centre_alpha > 0.05,
      "the volume is in the frame (max alpha {:.3f}, centre {:.3f})".format(max(alpha),
                                                                          centre_alpha))
corner_alpha = max(alpha[0], alpha[w - 1], alpha[-1], alpha[-w])
check(corner_alpha < 0.05, "and not everywhere (corners {:.3f})".format(corner_alpha))
print("blender add-on: all checks passed")
