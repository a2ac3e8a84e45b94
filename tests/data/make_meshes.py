#!/usr/bin/env python3
"""Writes the small analytic meshes of scenes/meshes and the import fixtures of tests/data/meshes.

Run from the repository root: python3 tests/data/make_meshes.py. The outputs are committed; this
script documents exactly what they are (no numpy needed).
"""
import base64
import math
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE_MESHES = os.path.join(ROOT, "scenes", "meshes")
FIXTURES = os.path.join(ROOT, "tests", "data", "meshes")

CUBE_V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
# Outward-facing (counter-clockwise seen from outside) triangles of the unit cube, 0-based.
CUBE_F = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
          (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
TETRA_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def icosphere(subdivisions, radius):
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(k * k for k in v)) for c in v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][i] + verts[b][i]) / 2 for i in range(3)]
                n = math.sqrt(sum(c * c for c in m))
                verts.append(tuple(c / n for c in m))
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return [tuple(radius * c for c in v) for v in verts], faces


def write_obj(path, verts, faces, comment):
    with open(path, "w") as f:
        f.write("# %s\n" % comment)
        for v in verts:
            f.write("v %.9g %.9g %.9g\n" % v)
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


def write_off(path, verts, faces):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(verts), len(faces)))
        for v in verts:
            f.write("%.9g %.9g %.9g\n" % v)
        for a, b, c in faces:
            f.write("3 %d %d %d\n" % (a, b, c))


def write_ply_colored(path, verts, faces, colors):
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex %d\n" % len(verts))
        f.write("property float x\nproperty float y\nproperty float z\n")
        f.write("property uchar red\nproperty uchar green\nproperty uchar blue\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(faces))
        for v, c in zip(verts, colors):
            f.write("%g %g %g %d %d %d\n" % (v + c))
        for a, b, c in faces:
            f.write("3 %d %d %d\n" % (a, b, c))


def normal(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    length = math.sqrt(sum(k * k for k in n)) or 1.0
    return tuple(k / length for k in n)


def write_stl_binary(path, verts, faces):
    with open(path, "wb") as f:
        f.write(b"volmorph test cube".ljust(80, b" "))
        f.write(struct.pack("<I", len(faces)))
        for face in faces:
            tri = [verts[i] for i in face]
            f.write(struct.pack("<3f", *normal(*tri)))
            for v in tri:
                f.write(struct.pack("<3f", *v))
            f.write(struct.pack("<H", 0))


def write_stl_ascii(path, verts, faces):
    with open(path, "w") as f:
        f.write("solid tetra\n")
        for face in faces:
            tri = [verts[i] for i in face]
            f.write("  facet normal %g %g %g\n    outer loop\n" % normal(*tri))
            for v in tri:
                f.write("      vertex %g %g %g\n" % v)
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid tetra\n")


def write_gltf(path, verts, faces):
    """A glTF 2.0 file with its buffer embedded as a data URI; the node translates by (10, 0, 0)."""
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx = b"".join(struct.pack("<3H", *f) for f in faces)
    buf = pos + idx
    lo = [min(v[i] for v in verts) for i in range(3)]
    hi = [max(v[i] for v in verts) for i in range(3)]
    import json
    doc = {
        "asset": {"version": "2.0", "generator": "volmorph tests/data/make_meshes.py"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [10.0, 0.0, 0.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(buf),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3",
                       "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5123, "count": 3 * len(faces), "type": "SCALAR"}],
    }
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def main():
    os.makedirs(FIXTURES, exist_ok=True)
    sv, sf = icosphere(4, 0.5)
    write_obj(os.path.join(SCENE_MESHES, "sphere.obj"), sv, sf,
              "icosphere, radius 0.5 world units, 4 subdivisions (tests/data/make_meshes.py)")
    write_obj(os.path.join(SCENE_MESHES, "cube.obj"), CUBE_V, CUBE_F,
              "unit cube centred at the origin (tests/data/make_meshes.py)")

    F = FIXTURES
    write_obj(os.path.join(F, "cube.obj"), CUBE_V, CUBE_F, "unit cube")
    write_off(os.path.join(F, "tetra.off"), TETRA_V, TETRA_F)
    colors = [(255, 0, 0), (0, 255, 0), (0, 0, 255), (255, 255, 255)]
    write_ply_colored(os.path.join(F, "tetra_colors.ply"), TETRA_V, TETRA_F, colors)
    write_stl_binary(os.path.join(F, "cube_binary.stl"), CUBE_V, CUBE_F)
    write_stl_ascii(os.path.join(F, "tetra_ascii.stl"), TETRA_V, TETRA_F)
    write_gltf(os.path.join(F, "tetra.gltf"), TETRA_V, TETRA_F)
    # Quads, triangulated on import: a cube of 6 quads.
    with open(os.path.join(F, "cube_quads.obj"), "w") as f:
        f.write("# unit cube as six quads\n")
        for v in CUBE_V:
            f.write("v %g %g %g\n" % v)
        for q in [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]:
            f.write("f %d %d %d %d\n" % q)
    # Topology cases.
    write_obj(os.path.join(F, "open_cube.obj"), CUBE_V, CUBE_F[2:], "unit cube missing one side")
    write_obj(os.path.join(F, "flipped_cube.obj"), CUBE_V,
              [CUBE_F[0][::-1]] + CUBE_F[1:], "unit cube with one triangle wound the wrong way")
    fin = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1)]
    write_obj(os.path.join(F, "nonmanifold.obj"), fin, [(0, 1, 2), (1, 0, 3), (0, 1, 4)],
              "three triangles sharing the edge 1-2")
    two = CUBE_V + [(x + 3, y, z) for x, y, z in CUBE_V]
    write_obj(os.path.join(F, "two_cubes.obj"), two,
              CUBE_F + [(a + 8, b + 8, c + 8) for a, b, c in CUBE_F], "two separate unit cubes")
    write_obj(os.path.join(F, "degenerate.obj"), CUBE_V + [(2, 0, 0), (3, 0, 0), (4, 0, 0)],
              CUBE_F + [(8, 9, 10)], "unit cube plus one zero-area (collinear) triangle")
    # Bad files.
    with open(os.path.join(F, "nan.obj"), "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")
    with open(os.path.join(F, "inf.off"), "w") as f:
        f.write("OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n")
    open(os.path.join(F, "empty.obj"), "w").close()
    with open(os.path.join(F, "no_faces.obj"), "w") as f:
        f.write("# vertices and no faces\nv 0 0 0\nv 1 0 0\nv 0 1 0\n")
    with open(os.path.join(F, "all_degenerate.obj"), "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    with open(os.path.join(F, "garbage.stl"), "wb") as f:
        # Deterministic pseudo-random bytes (a linear congruential generator).
        x = 12345
        data = bytearray()
        for _ in range(600):
            x = (1103515245 * x + 12345) % 2 ** 31
            data.append(x >> 16 & 0xFF)
        f.write(bytes(data))
    with open(os.path.join(F, "truncated.ply"), "w") as f:
        f.write("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0\n1 0 0\n")
    with open(os.path.join(F, "truncated_binary.stl"), "wb") as f:
        f.write(b"truncated".ljust(80, b" ") + struct.pack("<I", 12) + b"\0" * 100)


if __name__ == "__main__":
    main()
