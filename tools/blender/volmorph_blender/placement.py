# Feature elements as Blender transforms, and back. A volmorph scene is y-up, Blender z-up: the
# add-on puts everything of a scene under one root empty turned 90 degrees about x, so that each
# child's local transform is in the scene's own coordinates (world units, as the file writes them).
import math

from mathutils import Matrix, Vector

# How an empty draws each feature type, and its display size: a box is its box (a cube empty of
# size 0.5 scaled by the element's scales), a rectangle its rectangle in the xy plane (an image
# empty's frame), a segment its length along x (the plain axes' x line), a point a small sphere.
DISPLAY = {
    "point": ("SPHERE", 0.03),
    "segment": ("PLAIN_AXES", 0.5),
    "rectangle": ("IMAGE", 1.0),
    "box": ("CUBE", 0.5),
}

ROOT_ROTATION = (math.pi / 2, 0.0, 0.0)

# Digits a value moved in the viewport is written with: a tenth of a micrometre at metre scale,
# and no float32 noise in the file.
DIGITS = 7


def side_matrix(side):
    """The 4x4 local transform of a pair side: translation origin, rotation the axes (columns x,
    y, z), scale the element's scales."""
    x, y, z = (Vector(a) for a in side["axes"])
    rotation = Matrix((x, y, z)).transposed().to_4x4()
    matrix = rotation @ Matrix.Diagonal((*side["scale"], 1.0))
    matrix.translation = Vector(side["origin"])
    return matrix


def side_from_matrix(matrix):
    """A pair side from a local transform: its origin, axes (x and y; z follows) and scales,
    rounded to DIGITS decimals. A mirrored transform comes out with a negative scale, which the
    scene refuses with its reason."""
    location, rotation, scale = matrix.decompose()
    axes = rotation.to_matrix()
    r = lambda v: tuple(round(float(c), DIGITS) for c in v)
    x, y = axes.col[0], axes.col[1]
    return {"origin": r(location), "axes": (r(x), r(y), r(x.cross(y))), "scale": r(scale)}


def moved(a, b, tolerance=1e-6):
    """Whether two transforms differ by more than float32 noise."""
    return any(abs(a[i][j] - b[i][j]) > tolerance for i in range(4) for j in range(4))
