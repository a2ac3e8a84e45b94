"""Hoppe's SphereParam as sphere_bench.sh's anchor: meshes to and from his .m format.

  to-m MESH.off OUT.m   an OFF mesh as "Vertex i  x y z" and "Face j  a b c" lines (1-based)
  efficiency MESH.m     the L2 stretch efficiency (Praun and Hoppe 2003) of the map in the
                        vertices' {sph=(x y z)}, by the measure volmorph reports
                        (surface/SphereStretch.cpp: chord triangles, the sphere scaled to the
                        mesh's area), and the triangles it turns over (sign of det, in doubles)
"""
import math
import re
import sys


def to_m(off, out):
    lines = [l.split("#")[0].split() for l in open(off)]
    lines = [l for l in lines if l]
    head = lines[0][1:] if len(lines[0]) > 1 else lines[1]  # "OFF nv nf ne" or "OFF" then counts
    start = 1 if len(lines[0]) > 1 else 2
    nv, nf = int(head[0]), int(head[1])
    with open(out, "w") as f:
        for i, l in enumerate(lines[start:start + nv]):  # x y z, then any colour
            f.write("Vertex %d  %s %s %s\n" % (i + 1, l[0], l[1], l[2]))
        for j, l in enumerate(lines[start + nv:start + nv + nf]):
            n = int(l[0])
            f.write("Face %d  %s\n" % (j + 1, " ".join(str(int(v) + 1) for v in l[1:1 + n])))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def efficiency(path):
    pos, sph, faces = {}, {}, []
    vertex = re.compile(r"Vertex\s+(\d+)\s+(\S+)\s+(\S+)\s+(\S+).*sph=\((\S+) (\S+) (\S+)\)")
    for line in open(path):
        if line.startswith("Vertex"):
            m = vertex.match(line)
            i = int(m.group(1))
            pos[i] = tuple(map(float, m.group(2, 3, 4)))
            s = tuple(map(float, m.group(5, 6, 7)))
            r = math.sqrt(dot(s, s))
            sph[i] = (s[0] / r, s[1] / r, s[2] / r)
        elif line.startswith("Face"):
            faces.append(tuple(int(v) for v in line.split()[2:5]))
    mesh_area = chord_area = stretch = 0.0
    turned = 0
    for a, b, c in faces:
        q0, q1, q2 = pos[a], pos[b], pos[c]
        p0, p1, p2 = sph[a], sph[b], sph[c]
        if dot(p0, cross(p1, p2)) <= 0:
            turned += 1
        e01, e02, e12 = sub(p1, p0), sub(p2, p0), sub(p2, p1)
        ca = 0.5 * math.sqrt(dot(cross(e01, e02), cross(e01, e02)))
        area = 0.5 * math.sqrt(dot(cross(sub(q1, q0), sub(q2, q0)), cross(sub(q1, q0), sub(q2, q0))))
        d21, d20, d10 = sub(q2, q1), sub(q2, q0), sub(q1, q0)
        j2 = (dot(e01, e02) * dot(d21, d21) - dot(e01, e12) * dot(d20, d20)
              + dot(e02, e12) * dot(d10, d10)) / (4 * ca * ca)
        mesh_area += area
        chord_area += ca
        stretch += area * 0.5 * j2
    print("stretch efficiency %.3f, %d turned over" %
          (1.0 / (stretch / mesh_area * chord_area / mesh_area), turned))


if __name__ == "__main__":
    if sys.argv[1] == "to-m":
        to_m(sys.argv[2], sys.argv[3])
    else:
        efficiency(sys.argv[2])
