"""Readers and measures for the surface-morph command-line tests (surface_morph.sh, surface_star.sh,
surface_disk.sh): volmorph's binary PLY frames, OBJ and OFF inputs, a triangle mesh's volume and
area."""
import struct


def read_ply(path):
    """A frame's vertices (x y z vx vy vz, then r g b a when the frame has colours) and triangles."""
    head, body = open(path, "rb").read().split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    assert lines[1] == "format binary_little_endian 1.0", lines[1]
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in lines if l.startswith("element face")).split()[2])
    props = [l.split()[2] for l in lines if l.startswith("property float")]
    assert props == ["x", "y", "z", "vx", "vy", "vz"], props
    colours = "property uchar red" in lines
    layout, stride = ("<6f4B", 28) if colours else ("<6f", 24)
    verts = [struct.unpack_from(layout, body, i * stride) for i in range(nv)]
    face = 13 + 25 * len(uv_sets(lines))  # each texture coordinate set: a count and six floats
    assert len(body) == nv * stride + nf * face, (len(body), nv, nf)
    faces = [struct.unpack_from("<B3i", body, nv * stride + face * k)[1:] for k in range(nf)]
    return verts, faces


def read_frames(out, count):
    """Frames m.0001.ply .. m.COUNT.ply in `out`, asserted to share one connectivity."""
    frames = [read_ply("%s/m.%04d.ply" % (out, f)) for f in range(1, count + 1)]
    for verts, faces in frames:
        assert len(verts) == len(frames[0][0]) and faces == frames[0][1], "connectivity differs"
    return frames


def check_ends(frames, ends):
    """Each end (frame index, (points, triangles) of its input, rgba): the frame encloses the
    input's volume and has its area (1e-5: float PLY), every vertex that colour."""
    for f, (pts, tris), colour in ends:
        got, want = measure(frames[f][0], frames[f][1]), measure(pts, tris)
        for g, w, what in zip(got, want, ("volume", "area")):
            assert abs(g / w - 1) < 1e-5, "frame %d's %s %g, the input's %g" % (f + 1, what, g, w)
        assert all(v[6:] == colour for v in frames[f][0]), "colour of frame %d" % (f + 1)


def uv_sets(lines):
    return [l.split()[4] for l in lines if l.startswith("property list uchar float")]


def read_ply_uvs(path):
    """A frame's texture coordinate sets by name (texcoord, texcoord_source, texcoord_target), each
    a list of (u, v) per triangle corner."""
    head, body = open(path, "rb").read().split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    nf = int(next(l for l in lines if l.startswith("element face")).split()[2])
    stride = 28 if "property uchar red" in lines else 24
    names = uv_sets(lines)
    out = {n: [] for n in names}
    at = nv * stride
    for _ in range(nf):
        at += 13
        for n in names:
            assert body[at] == 6
            vals = struct.unpack_from("<6f", body, at + 1)
            out[n] += [(vals[0], vals[1]), (vals[2], vals[3]), (vals[4], vals[5])]
            at += 25
    return out


def read_obj_uvs(path):
    """Per triangle corner, the (u, v) its `f` line names (OBJ with vt)."""
    vt, out = [], []
    for l in open(path):
        w = l.split()
        if w and w[0] == "vt":
            vt.append((float(w[1]), float(w[2])))
        if w and w[0] == "f":
            out += [vt[int(x.split("/")[1]) - 1] for x in w[1:4]]
    return out


def read_obj(path):
    """Positions and triangles (polygons fanned)."""
    pts, tris = [], []
    for l in open(path):
        w = l.split()
        if w and w[0] == "v":
            pts.append(tuple(map(float, w[1:4])))
        if w and w[0] == "f":
            idx = [int(x.split("/")[0]) - 1 for x in w[1:]]
            tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1)]
    return pts, tris


def read_off(path, shift=(0.0, 0.0, 0.0)):
    """Positions moved by `shift` and triangles (polygons fanned)."""
    words = open(path).read().split()
    nv, nf = int(words[1]), int(words[2])
    vals = words[4:]
    pts = [tuple(float(vals[3 * i + c]) + shift[c] for c in range(3)) for i in range(nv)]
    k, tris = 3 * nv, []
    for _ in range(nf):
        n = int(vals[k]); idx = list(map(int, vals[k + 1:k + 1 + n])); k += 1 + n
        tris += [(idx[0], idx[j], idx[j + 1]) for j in range(1, n - 1)]
    return pts, tris


def measure(pts, tris):
    """Enclosed volume and area (the first three coordinates of each point)."""
    vol = area = 0.0
    for a, b, c in tris:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = pts[a][:3], pts[b][:3], pts[c][:3]
        vol += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
        ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
        area += 0.5 * ((uy * vz - uz * vy) ** 2 + (uz * vx - ux * vz) ** 2 + (ux * vy - uy * vx) ** 2) ** 0.5
    return vol / 6, area
