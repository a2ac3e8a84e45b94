// The surface stage (blend.mode = "surface"): the first half of the lecture volmorph comes from.
// Two triangle meshes are put into correspondence (one connectivity for both, each vertex with a
// place on each surface), then every in-between is that connectivity with each vertex between its
// two places: one mesh per frame, the same vertex count and triangles at every t, with the exact
// velocity of each vertex.
//
// Reads meshes (Mesh.h) and knows nothing of voxels, warps or blends: the scene's schedules are
// applied by its caller, which passes the shape's and the colour's tau and turns d position / d tau
// into world units per second.
#pragma once

#include <volmorph/Mesh.h>
#include <volmorph/core/Interrupter.h>
#include <volmorph/SurfaceSettings.h>

#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace volmorph {

/// One in-between, in double precision (the ends reproduce the inputs and the straight line is
/// exact to double rounding; Mesh's floats are for consumers that want them: mesh()).
struct SurfaceFrame {
    std::vector<Vec3d> points;    ///< at the shape's tau, world units
    std::vector<Vec3I> triangles; ///< the same at every tau
    /// Linear RGB at the colour's tau; empty when neither input has colours.
    std::vector<Vec3f> colors;
    /// d position / d tau of each vertex, world units per unit of the shape's tau (exact: the
    /// derivative of what `points` holds, not a difference of frames).
    std::vector<Vec3d> velocity;
    /// Per triangle corner (3 per triangle), texture coordinates: `uvs` at the colour's tau, the
    /// source's and the target's in `sourceUVs` and `targetUVs` (a shader blends the two
    /// textures by the same tau); all empty when neither input has them.
    std::vector<Vec2f> uvs, sourceUVs, targetUVs;

    /// Points rounded to float, the triangles, colours and (at tau) texture coordinates, topology
    /// analysed.
    Mesh mesh() const;
};

/// Under a timing (LocalTime.h), a place's time as the caller's schedule makes it: tau there in
/// [0, 1], d tau / d t, and grad tau per world unit.
struct PlaceTau {
    double tau = 0.0;
    double dt = 0.0;
    Vec3d gradient{0.0};
};
using PlaceTime = std::function<PlaceTau(const Vec3d& place)>;

class SurfaceMorpher {
public:
    /// Puts `source` and `target` (world units) into correspondence as `spec` says and prepares
    /// the interpolation (for "arap", one sparse factorization for every frame). Throws UserError
    /// at `spec`'s location when the chosen correspondence does not apply to the meshes (naming
    /// the mesh file and what was found); Interrupted when `interrupter` asks to stop.
    SurfaceMorpher(const Mesh& source, const Mesh& target, const SurfaceSpec& spec,
                   Interrupter* interrupter = nullptr);
    ~SurfaceMorpher();
    SurfaceMorpher(SurfaceMorpher&&) noexcept;
    SurfaceMorpher& operator=(SurfaceMorpher&&) noexcept;

    /// The in-between at `shapeTau` (positions) and `colorTau` (colours), each in [0, 1]: the
    /// source's at 0 and the target's at 1.
    SurfaceFrame frame(double shapeTau, double colorTau) const;
    /// The in-between under a timing: each vertex at the shape's tau of its own place, the point
    /// of its straight path x(s) = a + s (b - a) where the place's tau is s itself (one exists, s
    /// in [0, 1]; Newton's steps kept in a bisection's bracket), and with "arap" each triangle at
    /// its corners' mean tau; each vertex's colour at the colour's tau where it is. `velocity` is
    /// then d position / d t, world units per unit t, exact: d s / d t = tau_t / (1 - grad tau .
    /// (b - a)), 0 where that denominator is not positive (the place's time runs back along the
    /// path faster than the vertex moves: a fold).
    SurfaceFrame frame(const PlaceTime& shape, const PlaceTime& color) const;

    Correspondence correspondence() const; ///< the one used ("auto" resolved)
    size_t vertexCount() const;
    size_t triangleCount() const;
    /// Merged correspondences: the vertices that are crossings of an edge of one input with an
    /// edge of the other (the rest are the inputs' own vertices); 0 for the identity.
    size_t crossings() const;
    /// star: the point each mesh was projected from (given or found), world units.
    std::optional<std::pair<Vec3d, Vec3d>> kernels() const;
    /// sphere: each mesh's spherical map's L2 stretch efficiency (Praun and Hoppe 2003: 1 for a
    /// map without stretch, lower for more).
    std::optional<std::pair<double, double>> stretchEfficiency() const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace volmorph
