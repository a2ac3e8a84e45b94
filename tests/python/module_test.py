"""The Python module against the command line: the same grids, the same frames, the same errors.

Run by CTest (tests/CMakeLists.txt) as `python3 module_test.py CLASS` with PYTHONPATH=build/python
and VOLMORPH (the program) and VOLMORPH_SOURCE_DIR in the environment; each class is one test.
"""

import difflib
import os
import pathlib
import pydoc
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy
import pyopenvdb

import volmorph

EXE = os.environ["VOLMORPH"]
SOURCE = pathlib.Path(os.environ["VOLMORPH_SOURCE_DIR"])
SCENES = SOURCE / "scenes"


def run(*args):
    done = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True)
    if done.returncode != 0:
        raise AssertionError("volmorph {} failed: {}".format(" ".join(map(str, args)), done.stderr))
    return done.stdout


def dense(grid):
    """The grid over its active bounding box as a numpy array (tiles filled in), and the box."""
    lo, hi = grid.evalActiveVoxelBoundingBox()
    shape = tuple(h - l + 1 for l, h in zip(lo, hi))
    if isinstance(grid, pyopenvdb.Vec3SGrid):
        shape += (3,)
    array = numpy.zeros(shape, dtype=numpy.float32)
    grid.copyToArray(array, ijk=lo)
    return array, (lo, hi)


def assert_same_grids(test, ours, file_grids):
    test.assertEqual(sorted(ours), sorted(g.name for g in file_grids))
    for theirs in file_grids:
        mine = ours[theirs.name]
        test.assertIs(type(mine), type(theirs), theirs.name)
        test.assertEqual(mine.activeVoxelCount(), theirs.activeVoxelCount(), theirs.name)
        test.assertEqual(mine.transform.voxelSize(), theirs.transform.voxelSize(), theirs.name)
        test.assertEqual(mine.background, theirs.background, theirs.name)
        a, box_a = dense(mine)
        b, box_b = dense(theirs)
        test.assertEqual(box_a, box_b, theirs.name)
        test.assertTrue(numpy.array_equal(a, b), theirs.name + ": values differ")


def scene_copy(folder, name="bunny-to-knot.toml"):
    """The scene `name` copied into `folder`, its meshes and skies linked beside it."""
    for sub in ("meshes", "skies", "volumes"):
        os.symlink(SCENES / sub, folder / sub)
    shutil.copy(SCENES / name, folder / name)
    return folder / name


class Morph(unittest.TestCase):
    """Scene.morph(f) gives the grids `volmorph morph` writes, for every scene in scenes/."""

    def test_every_scene(self):
        with tempfile.TemporaryDirectory() as tmp:
            for path in sorted(SCENES.glob("*.toml")):
                with self.subTest(scene=path.name):
                    scene = volmorph.Scene(path)
                    frame = scene.frames[len(scene.frames) // 2]
                    pattern = os.path.join(tmp, path.stem + ".####.vdb")
                    run("morph", path, "--frames", frame, "-o", pattern, "-q")
                    written = pattern.replace("####", "%04d" % frame)
                    assert_same_grids(self, scene.morph(frame), pyopenvdb.readAll(written)[0])
                    # names="blender" as `--preset blender`: what the add-on's volume reads
                    if path.name == "sphere-to-box.toml":
                        run("morph", path, "--frames", frame, "-o", pattern, "-q",
                            "--preset", "blender")
                        grids = scene.morph(frame, names="blender")
                        self.assertIn("velocity", grids)
                        assert_same_grids(self, grids, pyopenvdb.readAll(written)[0])

    def test_path_writes_the_file_and_progress_is_told(self):
        with tempfile.TemporaryDirectory() as tmp:
            scene = volmorph.Scene(SCENES / "sphere-to-box.toml")
            out = os.path.join(tmp, "sub", "m.0002.vdb")
            grids = scene.morph(2, path=out)
            assert_same_grids(self, grids, pyopenvdb.readAll(out)[0])
            self.assertEqual(pyopenvdb.readAll(out)[1].get("volmorph_frame"), None)  # per grid
            self.assertEqual(grids["density"].metadata["volmorph_frame"], "2")
            told = []
            volmorph.voxelize(SCENES / "meshes" / "bunny.obj", resolution=200,
                              progress=lambda stage, pct: told.append((stage, pct)))
            self.assertTrue(told, "a voxelization of some tenths of a second tells its progress")
            self.assertTrue(all(stage == "voxelize" and -1 <= pct <= 100 for stage, pct in told),
                            told)

    def test_voxelize_equals_the_command(self):
        with tempfile.TemporaryDirectory() as tmp:
            mesh = SCENES / "meshes" / "cube.obj"
            out = os.path.join(tmp, "cube.vdb")
            run("voxelize", mesh, "-o", out, "--resolution", 40, "-q")
            assert_same_grids(self, volmorph.voxelize(mesh, resolution=40),
                              pyopenvdb.readAll(out)[0])


class Render(unittest.TestCase):
    """Scene.render(f) equals `volmorph render`'s frame, to half-float rounding."""

    def test_default_scene_frame(self):
        import OpenImageIO as oiio
        with tempfile.TemporaryDirectory() as tmp:
            path = SCENES / "bunny-to-knot.toml"
            run("render", path, "--frames", 12, "-o", os.path.join(tmp, "cli.####.exr"), "-q")
            ours = volmorph.Scene(path).render(12, path=os.path.join(tmp, "py.0012.exr"))
            self.assertEqual(ours.dtype, numpy.float32)
            self.assertEqual(ours.shape, (270, 480, 4))
            cli = oiio.ImageBuf(os.path.join(tmp, "cli.0012.exr"))
            theirs = cli.get_pixels(oiio.FLOAT, roi=oiio.ROI(0, 480, 0, 270, 0, 1, 0, 4))
            self.assertGreater(float(ours[..., 3].max()), 0.5)  # the morph is in the frame
            self.assertTrue(numpy.array_equal(ours.astype(numpy.float16).astype(numpy.float32),
                                              theirs))
            # the EXR written through the module is the command's, layers and all
            self.assertEqual(run("diff", os.path.join(tmp, "cli.0012.exr"),
                                 os.path.join(tmp, "py.0012.exr"), "--fail", 0).count("FAIL"), 0)


class Errors(unittest.TestCase):
    """Scene errors as SceneError with every file:line:col; a missing mesh as an OSError."""

    def test_bad_scene(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = scene_copy(pathlib.Path(tmp))
            text = path.read_text().replace("[volume]", "[volume]\nresolutoin = 3", 1)
            text = text.replace("samples = 6 ", "samples = -2 ", 1)
            path.write_text(text)
            with self.assertRaises(volmorph.SceneError) as caught:
                volmorph.Scene(path)
            self.assertIsInstance(caught.exception, ValueError)
            message = str(caught.exception)
            lines = text.splitlines()
            for key in ("resolutoin", "samples = -2"):
                line = next(i for i, l in enumerate(lines, 1) if l.startswith(key))
                self.assertIn("{}:{}:".format(path, line), message)
            self.assertEqual(len(caught.exception.diagnostics), 2)

    def test_missing_mesh(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = scene_copy(pathlib.Path(tmp))
            path.write_text(path.read_text().replace("meshes/bunny.obj", "meshes/nothing.obj"))
            with self.assertRaises(OSError) as caught:
                volmorph.Scene(path)
            self.assertIsInstance(caught.exception, FileNotFoundError)
            self.assertIsInstance(caught.exception, volmorph.SceneError)
            self.assertEqual(caught.exception.filename, os.path.join(tmp, "meshes", "nothing.obj"))
            self.assertIn(str(path) + ":", str(caught.exception))
            with self.assertRaises(volmorph.MissingFileError) as caught:
                volmorph.voxelize(os.path.join(tmp, "nothing.obj"))
            self.assertEqual(caught.exception.filename, os.path.join(tmp, "nothing.obj"))

    def test_frame_outside_and_bad_names(self):
        scene = volmorph.Scene(SCENES / "sphere-to-box.toml")
        with self.assertRaises(volmorph.SceneError):
            scene.morph(99)
        with self.assertRaises(ValueError):
            scene.morph(1, names="maya")

    def test_help_reads_well(self):
        text = pydoc.render_doc(volmorph, renderer=pydoc.plaintext)
        for words in ("class Scene", "voxelize(mesh_path", "KeyboardInterrupt", "file:line:col",
                      "morph(self, frame"):
            self.assertIn(words, text)


class Pairs(unittest.TestCase):
    """Editing pairs and saving changes only the edited lines."""

    def test_edit_one_value(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = scene_copy(pathlib.Path(tmp))
            before = path.read_text()
            scene = volmorph.Scene(path)
            pairs = scene.pairs
            self.assertEqual([p.type for p in pairs], ["box", "point", "point"])
            pairs[1].target["origin"] = (0.125, -0.25, 0.5)
            scene.pairs = pairs
            self.assertEqual(scene.pairs[1].target["origin"], (0.125, -0.25, 0.5))
            self.assertEqual(scene.pairs[0], pairs[0])
            scene.save()
            after = path.read_text()
            changed = [l for l in difflib.ndiff(before.splitlines(), after.splitlines())
                       if l[:1] in "+-"]
            self.assertEqual(len(changed), 2, changed)  # one line out, one in
            self.assertIn("[0.125, -0.25, 0.5]", changed[1])
            run("check", path)

    def test_add_remove_and_refuse(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = scene_copy(pathlib.Path(tmp))
            before = path.read_text()
            scene = volmorph.Scene(path)
            pairs = scene.pairs
            pairs.append(volmorph.Pair("segment",
                                       {"origin": (0, 0.1, 0), "scale": (0.3, 1, 1)},
                                       {"origin": (0, 0.2, 0), "scale": (0.4, 1, 1)}))
            scene.pairs = pairs
            self.assertEqual(len(scene.pairs), 4)
            bad = scene.pairs
            bad[0].source["scale"] = (0, 1, 1)
            with self.assertRaises(volmorph.SceneError):
                scene.pairs = bad
            self.assertEqual(len(scene.pairs), 4)  # unchanged
            scene.pairs = scene.pairs[:3]
            out = pathlib.Path(tmp) / "again.toml"
            scene.save(out)
            self.assertEqual(out.read_text(), before)


class Interrupt(unittest.TestCase):
    """KeyboardInterrupt during a long render returns control within a second and leaves the
    interpreter (and the scene) usable, with no file at the output path."""

    def test_ctrl_c(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = scene_copy(pathlib.Path(tmp))
            text = path.read_text().replace("resolution = [480, 270]", "resolution = [1920, 1080]")
            path.write_text(text.replace("noise = 0.02", "noise = 0.0005").replace(
                "samples = 6 ", "samples = 4096 "))
            scene = volmorph.Scene(path)
            out = os.path.join(tmp, "frame.exr")

            def interrupt():
                time.sleep(4.0)  # into the render; a hang is CTest's timeout, the latency a benchmark's
                os.kill(os.getpid(), signal.SIGINT)

            threading.Thread(target=interrupt, daemon=True).start()
            with self.assertRaises(KeyboardInterrupt):
                scene.render(12, path=out)
            self.assertFalse(os.path.exists(out))
            grids = volmorph.Scene(SCENES / "sphere-to-box.toml").morph(1)
            self.assertGreater(grids["density"].activeVoxelCount(), 0)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0]] + sys.argv[1:], verbosity=2)
