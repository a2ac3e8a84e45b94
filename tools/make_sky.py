#!/usr/bin/python3
"""Writes scenes/skies/sky.exr: the demo's procedural lat-long sky (half-float RGB, 512 x 256).

A clear sky without its sun disc (the scene's sun is a directional light with an angular diameter,
which shadows crisply and costs nothing to sample): blue at the zenith, pale at the horizon, a warm
glow around the sun's direction, a dark brown ground below the horizon. Orientation as volmorph's
lat-long maps (render/include/volmorph/render/EnvironmentMap.h): y up, the image's centre looking
along +x. Radiance in Cycles' units (background strength 1): about 1.6 of irradiance on an
upward-facing surface.

usage: tools/make_sky.py OUT.exr   (needs numpy and oiiotool)
"""
import os
import subprocess
import sys
import tempfile

import numpy as np

WIDTH, HEIGHT = 512, 256
SUN = np.array([1.0, 1.0, 0.5]) / 1.5   # toward the default scene's sun (it travels -1, -1, -0.5)
ZENITH = np.array([0.10, 0.22, 0.58])
HORIZON = np.array([0.62, 0.70, 0.84])
GLOW = np.array([1.4, 1.05, 0.7])
GROUND = np.array([0.14, 0.12, 0.10])


def directions():
    v = (np.arange(HEIGHT) + 0.5) / HEIGHT
    u = (np.arange(WIDTH) + 0.5) / WIDTH
    theta = np.pi * v[:, None]
    phi = 2.0 * np.pi * (u[None, :] - 0.5)
    return np.stack([np.sin(theta) * np.cos(phi), np.cos(theta) * np.ones_like(phi),
                     np.sin(theta) * np.sin(phi)], axis=-1)


def sky(d):
    y = d[..., 1:2]
    t = 1.0 - np.exp(-3.5 * np.clip(y, 0.0, None))
    gamma = np.arccos(np.clip(d @ SUN, -1.0, 1.0))[..., None]
    above = HORIZON * (1.0 - t) + ZENITH * t + GLOW * (0.5 * np.exp(-gamma / 0.2) +
                                                      0.12 * np.exp(-gamma / 0.9))
    s = np.exp(30.0 * np.clip(y, None, 0.0))  # a soft horizon line
    below = GROUND * (1.0 - s) + HORIZON * 0.6 * s
    return np.where(y >= 0.0, above, below)


def main():
    out = sys.argv[1]
    d = directions()
    rgb = sky(d).astype(np.float32)
    cos_up = np.clip(d[..., 1], 0.0, None)
    solid = (2 * np.pi / WIDTH) * (np.pi / HEIGHT) * np.sin(np.arccos(d[..., 1]))
    irradiance = (rgb * (cos_up * solid)[..., None]).sum(axis=(0, 1))
    print("irradiance on an upward surface (R, G, B):", np.round(irradiance, 3))
    with tempfile.TemporaryDirectory() as tmp:
        pfm = os.path.join(tmp, "sky.pfm")
        with open(pfm, "wb") as f:  # PFM rows run bottom to top
            f.write(b"PF\n%d %d\n-1.0\n" % (WIDTH, HEIGHT))
            f.write(rgb[::-1].astype("<f4").tobytes())
        subprocess.run(["oiiotool", pfm, "-d", "half", "--compression", "zip", "-o", out],
                       check=True)


if __name__ == "__main__":
    main()
