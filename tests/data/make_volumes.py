#!/usr/bin/python3
"""Writes the small volume files of the bad-input cases and CLI tests (tests/data/volumes/).
Deterministic; run with Debian's python3 (pyopenvdb, package python3-openvdb):
    /usr/bin/python3 tests/data/make_volumes.py
- fog_ball.vdb: a fog ball of radius 0.5 (voxel 0.1), density 1 inside with a ramp across the
  surface; a float grid `temperature` (1 - y), a vec3 grid `vel` and a bool grid `ids` (not
  carried);
- nan_density.vdb: the same ball with one NaN voxel;
- frustum.vdb: a density grid on a frustum transform;
- heat_only.vdb: the ball's temperature alone (neither a density nor a level set);
- fog_ball_cut.vdb: fog_ball.vdb cut off after 150,000 bytes (a truncated file);
- complex.nii: a NIfTI-1 volume of complex numbers (a datatype volmorph does not read), its header
  written by hand (348 bytes, NIfTI-1's layout)."""
import math
import os
import struct

import pyopenvdb as vdb

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "volumes")
VOXEL = 0.1


def ball(nan=False):
    density = vdb.FloatGrid(0.0)
    density.name = "density"
    density.gridClass = vdb.GridClass.FOG_VOLUME
    heat = vdb.FloatGrid(0.0)
    heat.name = "temperature"
    vel = vdb.Vec3SGrid((0.0, 0.0, 0.0))
    vel.name = "vel"
    ids = vdb.BoolGrid(False)
    ids.name = "ids"
    grids = [density, heat, vel, ids]
    for g in grids:
        g.transform = vdb.createLinearTransform(voxelSize=VOXEL)
    accs = [g.getAccessor() for g in grids]
    n = 7
    for i in range(-n, n + 1):
        for j in range(-n, n + 1):
            for k in range(-n, n + 1):
                x, y, z = i * VOXEL, j * VOXEL, k * VOXEL
                d = math.sqrt(x * x + y * y + z * z) - 0.5
                rho = min(1.0, max(0.0, 0.5 - d / (2 * 1.5 * VOXEL)))
                if rho <= 0.0:
                    continue
                accs[0].setValueOn((i, j, k), rho)
                accs[1].setValueOn((i, j, k), 1.0 - y)
                accs[2].setValueOn((i, j, k), (0.0, 1.0, 0.0))
                accs[3].setValueOn((i, j, k), True)
    if nan:
        accs[0].setValueOn((0, 0, 0), float("nan"))
    return grids


def frustum():
    g = vdb.FloatGrid(0.0)
    g.name = "density"
    g.transform = vdb.createFrustumTransform(
        xyzMin=(0, 0, 0), xyzMax=(10, 10, 10), taper=0.5, depth=1.0, voxelSize=0.1)
    acc = g.getAccessor()
    for i in range(10):
        acc.setValueOn((i, 5, 5), 1.0)
    return [g]


def complex_nifti(path, n=4):
    header = bytearray(348)
    struct.pack_into("<i", header, 0, 348)                        # sizeof_hdr
    struct.pack_into("<8h", header, 40, 3, n, n, n, 1, 1, 1, 1)   # dim
    struct.pack_into("<hh", header, 70, 32, 64)                   # datatype COMPLEX64, bitpix
    struct.pack_into("<8f", header, 76, 1, 1, 1, 1, 1, 1, 1, 1)   # pixdim
    struct.pack_into("<f", header, 108, 352.0)                    # vox_offset
    struct.pack_into("<f", header, 112, 1.0)                      # scl_slope
    header[344:348] = b"n+1\0"                                   # magic: one-file NIfTI-1
    with open(path, "wb") as f:
        f.write(bytes(header) + bytes(4) + bytes(8 * n * n * n))


def main():
    os.makedirs(HERE, exist_ok=True)
    vdb.write(os.path.join(HERE, "fog_ball.vdb"), grids=ball())
    vdb.write(os.path.join(HERE, "nan_density.vdb"), grids=ball(nan=True)[:1])
    vdb.write(os.path.join(HERE, "frustum.vdb"), grids=frustum())
    vdb.write(os.path.join(HERE, "heat_only.vdb"), grids=ball()[1:2])
    with open(os.path.join(HERE, "fog_ball.vdb"), "rb") as whole:
        head = whole.read(150000)
    with open(os.path.join(HERE, "fog_ball_cut.vdb"), "wb") as cut:
        cut.write(head)
    complex_nifti(os.path.join(HERE, "complex.nii"))


if __name__ == "__main__":
    main()
