// Checks of a merged correspondence (star, sphere) for the surface stage's tests: each side's own
// vertices kept, every merged vertex on both input surfaces, the inputs' volumes and areas, nothing
// folded over; and where a landmark pair meets.
#pragma once

#include "surface/Correspondence.h"

#include "SurfaceChecks.h"

#include <volmorph/SurfaceMorph.h>

#include <gtest/gtest.h>

#include <openvdb/math/Proximity.h>

#include <string>
#include <vector>

namespace volmorph::test {

using detail::Corresponded;

inline std::vector<Vec3d> pointsOf(const Mesh& m)
{
    return {m.points.begin(), m.points.end()};
}

/// Checks a merge of `a` into `b`: each side's own vertices kept exactly, every merged vertex on
/// both surfaces, the merged meshes enclosing the inputs' volumes and areas, none of their
/// triangles facing against the input's.
inline void checkMerge(const Mesh& a, const Mesh& b, const Corresponded& c)
{
    const size_t na = a.points.size(), nb = b.points.size();
    ASSERT_EQ(c.source.size(), na + nb + c.crossings);
    ASSERT_EQ(c.target.size(), c.source.size());
    for (size_t i = 0; i < na; ++i) EXPECT_EQ(c.source[i], Vec3d(a.points[i]));
    for (size_t j = 0; j < nb; ++j) EXPECT_EQ(c.target[na + j], Vec3d(b.points[j]));
    for (const auto& [mesh, merged] : {std::pair{&a, &c.source}, std::pair{&b, &c.target}}) {
        const std::vector<Vec3d> p = pointsOf(*mesh);
        const auto [lo, hi] = mesh->bounds();
        const double diagonal = (hi - lo).length();
        double worst = 0.0;
        for (const Vec3d& x : *merged) worst = std::max(worst, distanceTo(p, mesh->triangles, x));
        EXPECT_LT(worst, 1e-9 * diagonal) << mesh->file;
        EXPECT_NEAR(volume(*merged, c.triangles) / volume(p, mesh->triangles), 1.0, 1e-9);
        EXPECT_NEAR(area(*merged, c.triangles) / area(p, mesh->triangles), 1.0, 1e-9);
        EXPECT_EQ(facingAgainst(*merged, c.triangles, p, mesh->triangles, diagonal), 0u)
            << mesh->file << ": merged triangles folded over";
    }
}

/// The nearest point of `m` to `p`.
inline Vec3d snapped(const Mesh& m, const Vec3d& p)
{
    const std::vector<Vec3d> pts = pointsOf(m);
    Vec3d best = p;
    double d = 1e300;
    for (const Vec3I& t : m.triangles) {
        Vec3d uvw;
        const Vec3d q =
            openvdb::math::closestPointOnTriangleToPoint(pts[t[0]], pts[t[1]], pts[t[2]], p, uvw);
        if ((q - p).length() < d) {
            d = (q - p).length();
            best = q;
        }
    }
    return best;
}

/// The merged vertex where landmark `l` meets: at the snapped source point on the source side and
/// the snapped target point on the target side (1e-9 of the size), or -1.
inline int meeting(const Corresponded& c, const Mesh& a, const Mesh& b, const SurfaceLandmark& l)
{
    const Vec3d pa = snapped(a, l.source), pb = snapped(b, l.target);
    for (size_t v = 0; v < c.source.size(); ++v)
        if ((c.source[v] - pa).length() < 1e-9 && (c.target[v] - pb).length() < 1e-9) return int(v);
    return -1;
}

/// The morpher's in-betweens at tau = 0 and 1 are the merge's two sides (1e-9 world units).
inline void expectEndsOnSides(const SurfaceMorpher& m, const Corresponded& c)
{
    ASSERT_EQ(m.vertexCount(), c.source.size());
    for (const auto& [tau, side] : {std::pair{0.0, &c.source}, std::pair{1.0, &c.target}}) {
        const SurfaceFrame f = m.frame(tau, tau);
        double worst = 0.0;
        for (size_t v = 0; v < f.points.size(); ++v)
            worst = std::max(worst, (f.points[v] - (*side)[v]).length());
        EXPECT_LT(worst, 1e-9) << "tau " << tau;
    }
}

/// The UserError `correspond` throws for these meshes with `spec`, "" when none.
inline std::string refusal(const Mesh& a, const Mesh& b, const SurfaceSpec& spec)
{
    try {
        detail::correspond(a, b, spec);
    } catch (const UserError& e) {
        return e.what();
    }
    return {};
}

} // namespace volmorph::test
