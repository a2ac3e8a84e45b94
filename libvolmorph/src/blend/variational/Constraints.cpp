#include "blend/variational/Constraints.h"

#include <openvdb/tools/Interpolation.h>

#include <openvdb/math/Operators.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

namespace volmorph::detail::variational {
namespace {

struct SurfacePoint {
    openvdb::Vec3d position; ///< on the zero set, world units
    openvdb::Vec3d normal;   ///< outward, unit
};

/// The band's voxels within one voxel of the zero set, each projected onto it along its gradient.
std::vector<SurfacePoint> surfacePoints(const openvdb::FloatGrid& sdf)
{
    const double voxel = sdf.voxelSize()[0];
    auto acc = sdf.getConstAccessor();
    std::vector<SurfacePoint> points;
    for (auto it = sdf.cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue() || std::abs(*it) >= voxel) continue;
        const openvdb::Coord ijk = it.getCoord();
        // Index-space central differences: distance per voxel.
        const openvdb::Vec3d g =
            openvdb::math::ISGradient<openvdb::math::CD_2ND>::result(acc, ijk) / voxel;
        const double length = g.length();
        if (length < 1e-6) continue; // a ridge of the distance: no normal there
        const openvdb::Vec3d n = g / length;
        points.push_back({sdf.indexToWorld(ijk) - n * (double(*it) / length), n});
    }
    return points;
}

using Cell = std::tuple<int64_t, int64_t, int64_t>;

Cell cellOf(const openvdb::Vec3d& p, double h)
{
    return {int64_t(std::floor(p.x() / h)), int64_t(std::floor(p.y() / h)),
            int64_t(std::floor(p.z() / h))};
}

/// The point nearest each occupied cell's centre, cells in order.
std::vector<SurfacePoint> onePerCell(const std::vector<SurfacePoint>& points, double h)
{
    std::map<Cell, std::pair<double, size_t>> best;
    for (size_t i = 0; i < points.size(); ++i) {
        const openvdb::Vec3d& p = points[i].position;
        const Cell c = cellOf(p, h);
        const openvdb::Vec3d centre((double(std::get<0>(c)) + 0.5) * h,
                                    (double(std::get<1>(c)) + 0.5) * h,
                                    (double(std::get<2>(c)) + 0.5) * h);
        const double d = (p - centre).lengthSqr();
        const auto found = best.find(c);
        if (found == best.end() || d < found->second.first) best[c] = {d, i};
    }
    std::vector<SurfacePoint> chosen;
    chosen.reserve(best.size());
    for (const auto& entry : best) chosen.push_back(points[entry.second.second]);
    return chosen;
}

/// About `count` of `points`, evenly over the surface: one per cell of a lattice whose spacing
/// is adjusted until the occupied cells number count to 1.15 count, then strided down to count.
std::vector<SurfacePoint> evenly(const std::vector<SurfacePoint>& points, size_t count,
                                 double voxel)
{
    if (points.size() <= count) return points;
    // The band's voxels within a voxel of the surface lie about 2 deep: area ~ points voxel^2 / 2.
    double h = std::sqrt(double(points.size()) * voxel * voxel / 2.0 / double(count));
    std::vector<SurfacePoint> chosen = onePerCell(points, h);
    for (int round = 0; round < 12; ++round) {
        if (chosen.size() >= count && double(chosen.size()) <= 1.15 * double(count)) break;
        h *=
            std::sqrt(double(chosen.size()) / double(count)) * (chosen.size() < count ? 0.97 : 1.0);
        chosen = onePerCell(points, h);
    }
    if (chosen.size() <= count) return chosen;
    std::vector<SurfacePoint> strided;
    strided.reserve(count);
    for (size_t k = 0; k < count; ++k) strided.push_back(chosen[k * chosen.size() / count]);
    return strided;
}

} // namespace

std::vector<Constraint> sampleConstraints(const openvdb::FloatGrid& sdf, size_t count,
                                          double offset, double w)
{
    const std::vector<SurfacePoint> surface = evenly(surfacePoints(sdf), count, sdf.voxelSize()[0]);
    if (surface.empty()) throw std::invalid_argument("a shape has no surface to constrain");
    std::vector<Constraint> constraints;
    constraints.reserve(kConstraintsPerPoint * surface.size());
    auto acc = sdf.getConstAccessor();
    // The shape's own distance at a partner (world units, positive inside as f is): about the
    // offset, less where the shape is thinner than twice it (+offset there would claim inside
    // what is near the other side); the offset itself beyond the grid's band.
    const auto depth = [&](const openvdb::Vec3d& p, double beyond) {
        const double d = openvdb::tools::BoxSampler::sample(acc, sdf.worldToIndex(p));
        return std::abs(d) < sdf.background() ? -d : beyond;
    };
    for (const SurfacePoint& s : surface) {
        const openvdb::Vec3d in = s.position - s.normal * offset,
                             out = s.position + s.normal * offset;
        constraints.push_back({Point4(s.position.x(), s.position.y(), s.position.z(), w), 0.0});
        constraints.push_back({Point4(in.x(), in.y(), in.z(), w), depth(in, offset)});
        constraints.push_back({Point4(out.x(), out.y(), out.z(), w), depth(out, -offset)});
    }
    return constraints;
}

} // namespace volmorph::detail::variational
