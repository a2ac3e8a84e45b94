// The surface stage's settings (blend.mode = "surface", the scene's [surface] table): how the two
// meshes are put into correspondence and how each vertex travels between its two positions.
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>

#include <optional>
#include <utility>
#include <vector>

namespace volmorph {

/// How a vertex of one mesh finds its place on the other.
enum class Correspondence {
    Auto,     ///< the first of the others that applies
    Identity, ///< the same vertex count and triangles: vertex i goes to vertex i
    Star,     ///< Kent, Carlson and Parent 1992: both projected from a kernel point, merged
    Sphere,   ///< genus 0: spherical parameterizations (Praun and Hoppe 2003), merged
    Disk,     ///< one boundary loop: harmonic maps onto the unit disk, merged
};

/// How a vertex moves from its source position to its target position.
enum class SurfaceInterpolation {
    /// As rigid as possible: each triangle's affine map from source to target split into a
    /// rotation and a stretch (polar decomposition), the rotation turned by angle and the stretch
    /// interpolated linearly, the vertices fitted to those triangles in the least-squares sense
    /// (Alexa et al. 2000; on surfaces, Xu et al. 2005, Poisson shape interpolation).
    Arap,
    Linear, ///< each vertex on the straight line between its two positions
};

/// A point of the source's surface that must meet a point of the target's (a scene's point
/// [[pair]] in surface mode): each snapped to its mesh's nearest point, world units.
struct SurfaceLandmark {
    Vec3d source, target;
    SourceLocation where; ///< the [[pair]]
};

struct SurfaceSpec {
    Correspondence correspondence = Correspondence::Auto;
    SurfaceInterpolation interpolation = SurfaceInterpolation::Arap;
    /// star only: a point inside each mesh from which all of its surface is seen (world units);
    /// unset: found from the mesh.
    std::optional<std::pair<Vec3d, Vec3d>> kernel;
    /// The merged correspondences (star, disk) make each pair meet; the identity ignores them.
    std::vector<SurfaceLandmark> landmarks;
    SourceLocation where; ///< the [surface] table, when the scene has one
    SourceLocation correspondenceWhere;
};

/// "identity", "star", "sphere", "disk" or "auto"; "arap" or "linear".
const char* name(Correspondence correspondence);
const char* name(SurfaceInterpolation interpolation);

} // namespace volmorph
