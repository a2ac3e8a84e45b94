// The stretch of a map from the unit sphere onto a mesh (Sander, Snyder, Gortler and Hoppe 2001;
// on the sphere, Praun and Hoppe 2003), and the local moves that lower it without turning a
// triangle over: the energy the spherical parameterization (SphereParam.h) minimizes one vertex at
// a time.
//
// Each triangle is measured flat: the chord triangle of its three directions against the mesh
// triangle. The L2 stretch of a triangle is sqrt((G^2 + g^2) / 2), G and g the singular values of
// the linear map from the chord triangle onto the mesh's; the energy of a vertex is the sum over
// its triangles of (mesh area) x (L2 stretch)^2, which grows without bound as a chord triangle
// loses its area, so a descent that starts from a map with no triangle turned over keeps none.
#pragma once

#include <volmorph/core/Math.h>

#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace volmorph::detail {

/// The smallest det(p, q, r) of three unit directions a triangle may keep (counter-clockwise seen
/// from outside; far above the 2^-40 grid the exact predicates round to).
inline constexpr double kMinTripleProduct = 1e-13;

struct StretchMesh {
    const std::vector<Vec3d>* points = nullptr; ///< the mesh, world units
    std::vector<Vec3d>* directions = nullptr;   ///< the map: per vertex, a unit vector
    /// The stretch energy of one triangle of an even map (each triangle 4 pi / F of the sphere,
    /// stretched by the mesh's area over that): evenStretch().
    double even = 0.0;
    /// Each chord triangle's shape term, (sum of squared edges) / (4 sqrt 3 area), 1 for an
    /// equilateral triangle and unbounded for a sliver, weighs kShapeWeight x `even`. A thin mesh
    /// triangle (the coarse levels of a quadric decimation have many) stretches little onto a thin
    /// chord triangle, so stretch alone lets the map's triangles go flat; the term keeps them from
    /// it.
    static constexpr double kShapeWeight = 1e-3;
    static double evenStretch(const std::vector<Vec3d>& points,
                              const std::vector<Vec3I>& triangles);

    /// (mesh area) x (L2 stretch)^2 of triangle (a, b, c) with `pa` in place of a's direction, plus
    /// its shape term; +infinity when the chord triangle is turned over or thinner than
    /// kMinTripleProduct.
    double energy(uint32_t a, const Vec3d& pa, uint32_t b, uint32_t c) const;
};

/// The triangles around one vertex v, each (b, c) with (v, b, c) counter-clockwise.
using Fan = std::vector<std::pair<uint32_t, uint32_t>>;

/// The sum of energy() over the triangles of `fan` with `at` in place of v's direction.
double fanEnergy(const StretchMesh& m, uint32_t v, const Vec3d& at, const Fan& fan);

/// Whether every triangle of `fan` stays counter-clockwise (and thicker than kMinTripleProduct)
/// with `at` in place of v's direction.
inline bool fanValid(const StretchMesh& m, uint32_t v, const Vec3d& at, const Fan& fan)
{
    return fanEnergy(m, v, at, fan) < std::numeric_limits<double>::infinity();
}

/// Moves vertex `v` of `m` by up to `iterations` descent steps (a finite-difference gradient in
/// the tangent plane, then a backtracking line search that accepts only a lower energy with every
/// triangle of `fan` still counter-clockwise). Returns whether it moved.
bool relaxVertex(const StretchMesh& m, uint32_t v, const Fan& fan, int iterations);

/// The map's L2 stretch efficiency over the whole mesh (Praun and Hoppe 2003): 1 / L2^2 after
/// scaling the sphere's chord triangles to the mesh's area; 1 for a map without stretch, lower for
/// more.
double stretchEfficiency(const std::vector<Vec3d>& points, const std::vector<Vec3d>& directions,
                         const std::vector<Vec3I>& triangles);

/// The signed area of the spherical triangle (p, q, r) (Van Oosterom and Strackee 1983), in
/// steradians; the areas of a one-to-one map's triangles add up to 4 pi.
double sphericalArea(const Vec3d& p, const Vec3d& q, const Vec3d& r);

} // namespace volmorph::detail
