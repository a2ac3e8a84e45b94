"""Renders a .vdb with Blender Cycles as volmorph's render-vdb would: the anchor of issue 33.

usage: blender -b --factory-startup --python tests/bench/cycles_render.py -- IN.vdb|IN.ply OUT.exr
           --voxel V --eye X,Y,Z --lookat X,Y,Z --fov DEG --res WxH --extinction S --albedo A
           [--color-grid Cd] [--sun DX,DY,DZ,STRENGTH[,R,G,B]] [--sun-angle DEG] [--sky R,G,B]
           [--sky-map LATLONG.exr] [--floor MESH.obj --floor-color R,G,B] [--bounces N]
           [--samples N] [--step-rate R] [--threads N]
           [--velocity-grid NAME --shutter FRAMES --fps F]

Every vector is in volmorph's frame (y up, world units); the sun's direction is the way its light
travels, its strength the irradiance (Cycles' sun strength, as volmorph's intensity). As NOTES.md
says: Blender places OpenVDB voxel (i, j, k) at (i + 0.5) voxel sizes, so the volume moves by half a
voxel back; Blender is z up, so the volume and every vector turn 90 degrees about x. The medium is a
Principled Volume whose Density multiplies the grid (extinction per world unit), Color is the
albedo (times the colour grid when given) and Absorption Color is black: extinction = Density,
albedo = Color. Linear interpolation, a box pixel filter one pixel wide (volmorph's stratified
samples), a transparent film (RGB premultiplied, A = coverage), no denoising, float EXR.
With --velocity-grid, Cycles blurs the volume along that grid (world units per second, Velocity
Unit = Second, scale 1) over a shutter of FRAMES frames centred on the frame, at F frames per
second (issue 36's cross-check: tests/bench/blender_motion_blur.sh).
Issue 34's shot: --sky-map lights with a lat-long image (an Environment Texture, closest pixel, as
volmorph reads it; Blender's equirectangular mapping of the turned world is volmorph's), --floor
adds an OBJ mesh (y up, turned like the rest) with a Diffuse BSDF of --floor-color, and diffuse
bounces as many as volume bounces (volmorph's bounces count every vertex, on a prop or in the
medium).
A surface morph's frame (issue 57): IN.ply as `volmorph morph` writes it (binary, x y z, uchar
colours as linear values times 255), turned like the rest, smooth-shaded, a Diffuse BSDF whose
colour is --albedo times the vertex colours (as volmorph renders a surface morph); --voxel is
then unused.
"""
import argparse
import struct
import math
import sys
import time

import bpy
import mathutils


def vec(text, n=3):
    values = [float(v) for v in text.split(",")]
    if len(values) < n:
        raise SystemExit("expected %d numbers, got %r" % (n, text))
    return values


def to_blender(v):
    """y-up (x, y, z) -> z-up (x, -z, y): a turn of 90 degrees about x."""
    return mathutils.Vector((v[0], -v[2], v[1]))


def parse():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser()
    p.add_argument("vdb")
    p.add_argument("out")
    p.add_argument("--voxel", type=float, required=True)
    p.add_argument("--grid", default="density")
    p.add_argument("--color-grid", default="")
    p.add_argument("--eye", required=True)
    p.add_argument("--lookat", required=True)
    p.add_argument("--fov", type=float, default=40.0)
    p.add_argument("--res", default="640x360")
    p.add_argument("--extinction", type=float, required=True)
    p.add_argument("--albedo", type=float, default=0.8)
    p.add_argument("--anisotropy", type=float, default=0.0)
    p.add_argument("--sun", default="")
    p.add_argument("--sky", default="")
    p.add_argument("--sky-map", default="")
    p.add_argument("--sun-angle", type=float, default=0.0)
    p.add_argument("--floor", default="")
    p.add_argument("--floor-color", default="0.8,0.8,0.8")
    p.add_argument("--bounces", type=int, default=16)
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--step-rate", type=float, default=0.1)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--velocity-grid", default="")
    p.add_argument("--shutter", type=float, default=0.0)
    p.add_argument("--fps", type=float, default=24.0)
    return p.parse_args(argv)


def albedo_times(nodes, links, albedo, attribute, socket):
    """Sets `socket` to the albedo, times the colour attribute `attribute` when one is named."""
    a = albedo
    if not attribute:
        socket.default_value = (a, a, a, 1.0)
        return
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_name = attribute
    mix = nodes.new("ShaderNodeMixRGB")
    mix.blend_type = "MULTIPLY"
    mix.inputs["Fac"].default_value = 1.0
    mix.inputs["Color2"].default_value = (a, a, a, 1.0)
    links.new(attr.outputs["Color"], mix.inputs["Color1"])
    links.new(mix.outputs["Color"], socket)


def volume_object(args):
    bpy.ops.object.volume_import(filepath=args.vdb, align="WORLD", location=(0, 0, 0))
    obj = bpy.context.selected_objects[0]
    obj.rotation_euler = (math.pi / 2, 0.0, 0.0)
    obj.location = to_blender([-0.5 * args.voxel] * 3)
    mat = bpy.data.materials.new("medium")
    mat.use_nodes = True
    mat.cycles.volume_interpolation = "LINEAR"
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    pv = nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Density"].default_value = args.extinction
    pv.inputs["Density Attribute"].default_value = args.grid
    pv.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    pv.inputs["Anisotropy"].default_value = args.anisotropy
    albedo_times(nodes, links, args.albedo, args.color_grid, pv.inputs["Color"])
    links.new(pv.outputs["Volume"], out.inputs["Volume"])
    obj.data.materials.append(mat)
    if args.velocity_grid:
        obj.data.velocity_grid = args.velocity_grid
        obj.data.velocity_unit = "SECOND"
        obj.data.velocity_scale = 1.0


PLY_TYPES = {"float": "f", "double": "d", "uchar": "B", "char": "b", "int": "i", "uint": "I",
             "short": "h", "ushort": "H"}


def read_ply(path):
    """Points, faces and linear vertex colours (None without) of a binary little-endian PLY."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    elements, current = [], None
    for line in data[:end].decode().splitlines():
        fields = line.split()
        if fields[0] == "element":
            current = (fields[1], int(fields[2]), [])
            elements.append(current)
        elif fields[0] == "property":
            current[2].append(fields[1:])
    at, points, colours, faces = end, [], [], []
    for name, count, props in elements:
        for _ in range(count):
            row = {}
            for prop in props:
                if prop[0] == "list":
                    (n,) = struct.unpack_from("<" + PLY_TYPES[prop[1]], data, at)
                    at += struct.calcsize(PLY_TYPES[prop[1]])
                    fmt = "<%d%s" % (n, PLY_TYPES[prop[2]])
                    row[prop[3]] = struct.unpack_from(fmt, data, at)
                    at += struct.calcsize(fmt)
                else:
                    (row[prop[1]],) = struct.unpack_from("<" + PLY_TYPES[prop[0]], data, at)
                    at += struct.calcsize(PLY_TYPES[prop[0]])
            if name == "vertex":
                points.append(to_blender([row["x"], row["y"], row["z"]]))
                if "red" in row:
                    colours.append([row[c] / 255.0 for c in ("red", "green", "blue")])
            elif name == "face":
                faces.append(list(row["vertex_indices"]))
    return points, faces, colours or None


def surface_object(args):
    """The PLY's mesh, smooth, Diffuse BSDF of --albedo times its vertex colours."""
    points, faces, colours = read_ply(args.vdb)
    mesh = bpy.data.meshes.new("surface")
    mesh.from_pydata(points, [], faces)
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    obj = bpy.data.objects.new("surface", mesh)
    bpy.context.scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("surface")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Roughness"].default_value = 0.0
    if colours:
        attribute = mesh.attributes.new("Col", "FLOAT_COLOR", "POINT")
        attribute.data.foreach_set("color", [v for c in colours for v in (c[0], c[1], c[2], 1.0)])
    albedo_times(nodes, links, args.albedo, "Col" if colours else "", bsdf.inputs["Color"])
    links.new(bsdf.outputs["BSDF"], nodes["Material Output"].inputs["Surface"])
    obj.data.materials.append(mat)


def camera(args, width):
    cam = bpy.data.cameras.new("camera")
    cam.sensor_fit = "HORIZONTAL"
    cam.angle = math.radians(args.fov)
    cam.clip_start = 1e-3
    obj = bpy.data.objects.new("camera", cam)
    bpy.context.scene.collection.objects.link(obj)
    eye, lookat = to_blender(vec(args.eye)), to_blender(vec(args.lookat))
    obj.location = eye
    obj.rotation_euler = (lookat - eye).to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = obj


def lights(args):
    if args.sun:
        s = vec(args.sun, 4)
        sun = bpy.data.lights.new("sun", "SUN")
        sun.energy = s[3]
        sun.angle = math.radians(args.sun_angle)
        if len(s) >= 7:
            sun.color = s[4:7]
        obj = bpy.data.objects.new("sun", sun)
        bpy.context.scene.collection.objects.link(obj)
        obj.rotation_euler = to_blender(s[:3]).to_track_quat("-Z", "Y").to_euler()
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    sky = vec(args.sky) if args.sky else [0.0, 0.0, 0.0]
    bg.inputs["Color"].default_value = (sky[0], sky[1], sky[2], 1.0)
    bg.inputs["Strength"].default_value = 1.0
    if args.sky_map:
        tex = world.node_tree.nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(args.sky_map)
        tex.interpolation = "Closest"
        world.node_tree.links.new(tex.outputs["Color"], bg.inputs["Color"])
    bpy.context.scene.world = world


def floor(args):
    """The OBJ's vertices and faces (y up, turned to z up), a Diffuse BSDF of --floor-color."""
    points, faces = [], []
    with open(args.floor) as f:
        for line in f:
            fields = line.split()
            if fields and fields[0] == "v":
                points.append(to_blender([float(v) for v in fields[1:4]]))
            elif fields and fields[0] == "f":
                faces.append([int(v.split("/")[0]) - 1 for v in fields[1:]])
    mesh = bpy.data.meshes.new("floor")
    mesh.from_pydata(points, [], faces)
    obj = bpy.data.objects.new("floor", mesh)
    bpy.context.scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("floor")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
    c = vec(args.floor_color)
    bsdf.inputs["Color"].default_value = (c[0], c[1], c[2], 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    out = mat.node_tree.nodes["Material Output"]
    mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    obj.data.materials.append(mat)


def settings(args):
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = args.samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = args.bounces + 1
    c.volume_bounces = args.bounces
    c.diffuse_bounces = args.bounces if args.floor or args.vdb.endswith(".ply") else 0
    c.glossy_bounces = c.transmission_bounces = 0
    # A volume's boundary is a transparent surface to Cycles' shadow rays: with no transparent
    # bounces the sun would never reach the inside.
    c.transparent_max_bounces = 256
    c.volume_step_rate = args.step_rate
    c.volume_max_steps = 100000
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.seed = 0
    scene.render.film_transparent = True
    w, h = (int(v) for v in args.res.split("x"))
    scene.render.resolution_x, scene.render.resolution_y = w, h
    scene.render.resolution_percentage = 100
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = args.out
    if args.velocity_grid and args.shutter > 0.0:
        scene.render.use_motion_blur = True
        scene.render.motion_blur_shutter = args.shutter
        c.motion_blur_position = "CENTER"
        scene.render.fps = int(round(args.fps))
        scene.render.fps_base = scene.render.fps / args.fps
    return w


def main():
    args = parse()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    width = settings(args)
    if args.vdb.endswith(".ply"):
        surface_object(args)
    else:
        volume_object(args)
    camera(args, width)
    lights(args)
    if args.floor:
        floor(args)
    start = time.time()
    bpy.ops.render.render(write_still=True)
    print("cycles: rendered %s in %.2f s" % (args.out, time.time() - start))


main()
