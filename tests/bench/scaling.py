#!/usr/bin/env python3
"""How volmorph scales with the voxel size (issue 38), not a test.

The default scene (scenes/bunny-to-knot.toml, about 1 world unit across) at N voxels across
(voxel_size = 1 / N), in sdf and in density mode:
  setup   wall time of `volmorph morph --frames 12` until frame 12 starts, with an empty voxel cache
          (voxelization, the blend's one-time work);
  frame   frame 12's own morph time, as the command reports it;
  render  wall time of `volmorph render --frames 12` from its first render stage on (after its own
          setup and morph; the voxel cache of the morph run is reused);
  peak    each command's peak resident memory (getrusage of the child, ru_maxrss).
Prints a Markdown table. A run that fails (for example refused by the memory guard) prints its
message in the row.

usage: tests/bench/scaling.py [--build build] [--across 250,500,1000] [--modes sdf,density]
                              [--resolution 640x360] [--no-render] [--memory-limit GIB]

--memory-limit is passed to both commands (their default is half the machine's memory: 2048 across
needs more).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "scenes", "bunny-to-knot.toml")
FRAME = 12


def scene_text(across, mode, resolution):
    """The default scene at `across` voxels, blend mode `mode`, meshes and sky by absolute path."""
    text = open(SCENE).read()
    scenes = os.path.dirname(SCENE)
    text = re.sub(r'(mesh|map) = "([^"]+)"',
                  lambda m: '%s = "%s"' % (m.group(1), os.path.join(scenes, m.group(2))), text)
    text, n = re.subn(r"^voxel_size = [0-9.]+", "voxel_size = %.9g" % (1.0 / across), text,
                      flags=re.M)
    assert n == 1, "the scene's voxel_size line moved"
    text, n = re.subn(r'^mode = "\w+"', 'mode = "%s"' % mode, text, flags=re.M)
    assert n == 1, "the scene's blend mode line moved"
    w, h = resolution.split("x")
    text, n = re.subn(r"^resolution = \[\d+, \d+\]", "resolution = [%s, %s]" % (w, h), text,
                      flags=re.M)
    assert n == 1, "the scene's render resolution line moved"
    return text


def run(command):
    """Runs command; returns (seconds, peak resident bytes, its output, return code)."""
    start = time.monotonic()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True)
    err = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.monotonic() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    return seconds, usage.ru_maxrss * 1024, err, child.returncode


def stage_start(err, name):
    """When the verbose stage `name` started (seconds since the command's start)."""
    for line in err.splitlines():
        m = re.match(r"volmorph:\s+([0-9.]+) s\s+(.*)$", line)
        if m and m.group(2).startswith(name):
            return float(m.group(1))
    return None


def frame_seconds(err):
    m = re.search(r"^frame %d \(t=[0-9.]+\):.* ([0-9.]+) s -> " % FRAME, err, flags=re.M)
    return float(m.group(1)) if m else None


def measure(build, across, mode, resolution, render, limit):
    volmorph = os.path.join(build, "bin", "volmorph")
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "scene.toml")
        open(scene, "w").write(scene_text(across, mode, resolution))
        cache = os.path.join(tmp, "cache")
        row = {"across": across, "mode": mode}
        extra = ["--memory-limit", str(limit)] if limit else []
        wall, peak, err, code = run([volmorph, "morph", scene, "--frames", str(FRAME), "-v",
                                     "--cache", cache, "-o", os.path.join(tmp, "m.####.vdb")] +
                                    extra)
        if code != 0:
            row["error"] = err.strip().splitlines()[-1] if err.strip() else "exit %d" % code
            return row
        row["setup"] = stage_start(err, "frame %d: morph" % FRAME)
        row["frame"] = frame_seconds(err)
        row["morph_peak"] = peak
        if render:
            wall, peak, err, code = run([volmorph, "render", scene, "--frames", str(FRAME), "-v",
                                         "--cache", cache, "-o", os.path.join(tmp, "r.####.exr")] +
                                        extra)
            if code != 0:
                row["error"] = err.strip().splitlines()[-1] if err.strip() else "exit %d" % code
                return row
            # `render` reports the whole frame (morph and render) on its frame line: the render
            # is what follows the morph, from its first render stage on.
            render_start = stage_start(err, "render: ")
            row["render"] = wall - render_start if render_start is not None else None
            row["render_peak"] = peak
        return row


def cell(row, key, scale=1.0, fmt="%.2f"):
    return fmt % (row[key] * scale) if row.get(key) is not None else "-"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--across", default="250,500,1000")
    parser.add_argument("--modes", default="sdf,density")
    parser.add_argument("--resolution", default="640x360")
    parser.add_argument("--no-render", action="store_true")
    parser.add_argument("--memory-limit", type=float, default=0.0)
    args = parser.parse_args()
    print("| across | mode | setup (s) | frame %d (s) | render (s) | morph peak (GB) | "
          "render peak (GB) |" % FRAME)
    print("|---|---|---:|---:|---:|---:|---:|")
    for across in [int(a) for a in args.across.split(",")]:
        for mode in args.modes.split(","):
            row = measure(args.build, across, mode, args.resolution, not args.no_render,
                          args.memory_limit)
            if "error" in row and "setup" not in row:
                print("| %d | %s | %s |" % (across, mode, row["error"]))
            else:
                print("| %d | %s | %s | %s | %s | %s | %s |%s" % (
                    across, mode, cell(row, "setup"), cell(row, "frame"), cell(row, "render"),
                    cell(row, "morph_peak", 1e-9), cell(row, "render_peak", 1e-9),
                    " " + row["error"] if "error" in row else ""))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
