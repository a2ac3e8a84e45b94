"""volmorph: feature-based volume morphing, from Python.

A scene file (TOML, as ``volmorph check`` reads it) says which mesh or volume becomes which, the
feature pairs that guide the warp, and how each frame is rendered. This module reads one and gives
what the command line writes, without a file in between:

>>> import volmorph
>>> scene = volmorph.Scene("scenes/bunny-to-knot.toml")
>>> scene.frames[:3]
[1, 2, 3]
>>> grids = scene.morph(12)               # {"sdf": pyopenvdb.FloatGrid, "density": ..., "Cd": ..., "vel": ...}
>>> image = scene.render(12)              # numpy float32, height x width x 4, RGBA premultiplied
>>> pairs = scene.pairs                   # [volmorph.Pair(type="box", source={...}, target={...}), ...]
>>> pairs[0].target["origin"] = (0.1, 0.2, 0.0)
>>> scene.pairs = pairs                   # written into the scene's text where each value is
>>> scene.save()                          # every other byte of the file kept

Grids are real ``pyopenvdb`` grids (Debian's python3-openvdb), ready for ``pyopenvdb.write`` or any
tool that takes them. World units throughout; velocity (``vel``) in world units per second.

Long calls (``Scene.morph``, ``Scene.render``, ``voxelize``) run with the GIL released; Ctrl-C
(KeyboardInterrupt) stops them within a second and leaves the scene usable. Each takes an optional
``progress(stage, percent)`` callback, called on the calling thread as the work moves (``percent``
is -1 for a stage that does not count).

Errors: a scene that is not valid raises ``SceneError`` (a ``ValueError``) whose text holds every
``file:line:col: message``; a file the scene names that does not exist raises
``MissingFileError`` (a ``FileNotFoundError`` and a ``SceneError``) with ``filename`` set.
"""

import os as _os

try:
    import pyopenvdb as _pyopenvdb  # registers the grid types the compiled half hands over
except ImportError as _error:  # pragma: no cover - a packaging problem, said plainly
    raise ImportError(
        "volmorph needs pyopenvdb (Debian's python3-openvdb, for /usr/bin/python3): " + str(_error)
    ) from _error

import numpy as _numpy

from . import _volmorph

__all__ = ["Scene", "Pair", "SceneError", "MissingFileError", "voxelize", "GRID_NAMES"]

SceneError = _volmorph.SceneError
SceneError.__doc__ = """A scene that is not valid: its text is every problem, one per line, as
``file:line:col: message``; ``diagnostics`` holds them as (file, line, column, message) tuples."""
MissingFileError = _volmorph.MissingFileError
MissingFileError.__doc__ = """A file the scene names (a mesh, a volume) does not exist: a
``FileNotFoundError`` whose ``filename`` is the path looked for, and a ``SceneError`` whose text
says where in the scene it is named."""

#: The grid names a morph's grids can take: volmorph's own (sdf, density, Cd, vel), Houdini's
#: (surface, density, Cd, vel) or Blender's (sdf, density, color, velocity).
GRID_NAMES = ("volmorph", "houdini", "blender")

_FEATURE_TYPES = ("point", "segment", "rectangle", "box")


def _wait(job, progress):
    """Waits for ``job`` a twentieth of a second at a time, so that Python's signal handlers run in
    between: a KeyboardInterrupt cancels the job, waits for it to stop (within a second) and goes
    on up. Returns the job's result, or raises what the job raised."""
    seen = None
    try:
        while not job.wait(0.05):
            if progress is not None:
                now = (job.stage(), job.percent())
                if now != seen and now[0]:  # nothing to tell before the first stage
                    seen = now
                    progress(*now)
    except BaseException:
        job.cancel()
        while not job.wait(0.05):
            pass
        raise
    return job.result()


def _element(side, what):
    """A pair side as a dict of tuples, checked for shape: origin (3), axes (2 or 3 rows of 3: x,
    y and, derived from them, z), scale (3, or one number for all)."""
    if not isinstance(side, dict):
        raise TypeError(what + ": expected a dict with origin, axes and scale")
    unknown = set(side) - {"origin", "axes", "scale"}
    if unknown:
        raise ValueError(what + ": unknown keys " + ", ".join(sorted(unknown)))
    origin = tuple(float(v) for v in side.get("origin", (0.0, 0.0, 0.0)))
    axes = [tuple(float(v) for v in row) for row in side.get("axes", ((1, 0, 0), (0, 1, 0)))]
    scale = side.get("scale", (1.0, 1.0, 1.0))
    if isinstance(scale, (int, float)):
        scale = (scale, scale, scale)
    scale = tuple(float(v) for v in scale)
    if len(origin) != 3 or len(scale) != 3 or len(axes) not in (2, 3) or any(len(a) != 3 for a in axes):
        raise ValueError(what + ": expected origin (3 numbers), axes (2 or 3 rows of 3), scale (3)")
    x, y = _numpy.array(axes[0]), _numpy.array(axes[1])
    if len(axes) == 3 and not _numpy.allclose(_numpy.cross(x, y), axes[2], atol=1e-5):
        raise ValueError(what + ": axes must be right-handed (z = x cross y); a mirrored frame "
                         "cannot be a feature's")
    return {"origin": origin, "axes": (axes[0], axes[1]), "scale": scale}


class Pair:
    """A feature pair: an element on the source and its counterpart on the target.

    ``type`` is "point", "segment", "rectangle" or "box" (it chooses the distance to the element;
    see the scene reference). ``source`` and ``target`` are dicts of ``origin`` (world units),
    ``axes`` (the element's x, y and z axes, unit length, right-handed; on assignment x and y
    suffice) and ``scale`` (the element's extent along its axes, world units).
    """

    __slots__ = ("type", "source", "target")

    def __init__(self, type="point", source=None, target=None):
        self.type = type
        self.source = dict(source or {"origin": (0.0, 0.0, 0.0)})
        self.target = dict(target or {"origin": (0.0, 0.0, 0.0)})

    def __repr__(self):
        return "volmorph.Pair(type={!r}, source={!r}, target={!r})".format(
            self.type, self.source, self.target)

    def __eq__(self, other):
        return (isinstance(other, Pair) and self.type == other.type
                and self.source == other.source and self.target == other.target)

    def _checked(self, index):
        what = "pairs[{}]".format(index)
        if self.type not in _FEATURE_TYPES:
            raise ValueError(what + ".type: expected one of " + ", ".join(_FEATURE_TYPES))
        return {"type": self.type, "source": _element(self.source, what + ".source"),
                "target": _element(self.target, what + ".target")}


def _pair_from(d):
    side = lambda s: {"origin": tuple(s["origin"]), "axes": tuple(tuple(a) for a in s["axes"]),
                      "scale": tuple(s["scale"])}
    return Pair(d["type"], side(d["source"]), side(d["target"]))


class Scene:
    """A volmorph scene file, read and validated.

    ``Scene(path)`` raises ``SceneError`` (every ``file:line:col: message``) when the scene is not
    valid and ``MissingFileError`` when a file it names does not exist. The voxels of its source
    and target come through volmorph's voxel cache, as on the command line.
    """

    def __init__(self, path):
        self._scene = _volmorph.Scene(_os.fspath(path))

    def __repr__(self):
        return "volmorph.Scene({!r})".format(self.path)

    @property
    def path(self):
        """The scene file's path, as given."""
        return self._scene.path()

    @property
    def frames(self):
        """The scene's frame numbers, in order (``[frames] first`` to ``last``)."""
        return self._scene.frames()

    @property
    def medium(self):
        """The scene's medium as its ``[render]`` sets it, for a renderer of one's own:
        ``extinction`` (per world unit at density 1), ``albedo``, ``anisotropy`` (Henyey-Greenstein
        g), ``emission`` (linear RGB per unit optical depth), and the frame rate ``fps``."""
        return self._scene.medium()

    @property
    def text(self):
        """The scene's text, with the edits made through ``pairs`` (saved or not)."""
        return self._scene.text()

    @property
    def pairs(self):
        """The feature pairs, in file order, as a list of ``Pair``.

        A copy: edit it, then assign it back (``scene.pairs = pairs``). Assigning writes each
        changed value where it stands in the scene's text, appends new pairs after the last and
        removes missing ones; the scene is then validated (``SceneError`` and nothing changed when
        it is not) and the next morph uses the new pairs. ``save()`` writes the text.
        """
        return [_pair_from(d) for d in self._scene.pairs()]

    @pairs.setter
    def pairs(self, pairs):
        pairs = list(pairs)
        if any(not isinstance(p, Pair) for p in pairs):
            raise TypeError("pairs: expected a list of volmorph.Pair")
        self._scene.set_pairs([p._checked(i) for i, p in enumerate(pairs)])

    def side_meshes(self):
        """The source and target meshes placed as the scene places them (its ``transform``s
        applied; world units): ``{"source": (vertices, triangles), "target": ...}``, numpy arrays
        of float32 N x 3 and uint32 M x 3; ``None`` for a side that is a volume."""
        out = {}
        for side, mesh in self._scene.side_meshes().items():
            if mesh is not None:
                points, triangles = mesh
                mesh = (_numpy.frombuffer(points, dtype=_numpy.float32).reshape(-1, 3),
                        _numpy.frombuffer(triangles, dtype=_numpy.uint32).reshape(-1, 3))
            out[side] = mesh
        return out

    def save(self, path=None):
        """Writes the scene's text to ``path`` (default: its own file), whole or not at all. Only
        the values changed through ``pairs`` differ from the file as read: comments, layout and
        every other value stay byte for byte. Paths in the scene stay relative to where it is
        written."""
        self._scene.save("" if path is None else _os.fspath(path))

    def morph(self, frame, path=None, names="volmorph", progress=None):
        """The in-between of ``frame`` as a dict from grid name to ``pyopenvdb`` grid: exactly the
        grids, active voxels and values ``volmorph morph`` writes (``sdf``, ``density``, ``Cd``,
        ``vel`` in world units per second over half a frame either way, and any grid the inputs
        carry). ``names`` is one of ``GRID_NAMES`` (``"blender"``: density, color, velocity, as
        Blender's volume objects read them). With ``path``, also writes the .vdb as the command
        does (whole or not at all)."""
        if names not in GRID_NAMES:
            raise ValueError("names: expected one of " + ", ".join(GRID_NAMES))
        job = self._scene.start_morph(int(frame), names, "" if path is None else _os.fspath(path))
        return _wait(job, progress)

    def render(self, frame, path=None, progress=None):
        """Frame ``frame`` rendered as ``volmorph render`` renders it (the scene's camera, lights,
        props, noise target and motion blur): a numpy float32 array of height x width x 4, linear
        RGBA, premultiplied, the first row the image's top. With ``path``, also writes the EXR the
        command writes (half float, with its layers), whole or not at all."""
        job = self._scene.start_render(int(frame), "" if path is None else _os.fspath(path))
        width, height, pixels = _wait(job, progress)
        return _numpy.frombuffer(pixels, dtype=_numpy.float32).reshape(height, width, 4)


def voxelize(mesh_path, voxel_size=None, resolution=None, progress=None):
    """The mesh at ``mesh_path`` (OBJ, PLY, STL, OFF, glTF, FBX, ... through Assimp) as grids, as
    ``volmorph voxelize`` makes them: ``sdf`` (signed distance in world units, a narrow band),
    ``density`` (fog, 1 inside) and ``Cd``. ``voxel_size`` in world units, or ``resolution``
    voxels across the mesh's larger extent (default 128). Holes are closed; a missing file raises
    ``MissingFileError``, an unreadable one ``SceneError``."""
    job = _volmorph.start_voxelize(_os.fspath(mesh_path),
                                   None if voxel_size is None else float(voxel_size),
                                   None if resolution is None else int(resolution))
    return _wait(job, progress)
