#include "blend/BlockClasses.h"

#include "warp/Stretch.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace volmorph::detail {

using openvdb::Coord;

bool BlockClasses::anyToEvaluate(const openvdb::CoordBBox& cells) const
{
    openvdb::CoordBBox b = cells >> size_t(3); // leaf coordinates
    b.intersect(leaves);
    for (int x = b.min().x(); x <= b.max().x(); ++x)
        for (int y = b.min().y(); y <= b.max().y(); ++y)
            for (int z = b.min().z(); z <= b.max().z(); ++z)
                if (at(Coord(x, y, z)) == 0) return true;
    return false;
}

std::vector<float> neighbourhoodMax(const std::vector<float>& values, const Coord& dim)
{
    auto index = [&dim](int x, int y, int z) { return (size_t(x) * dim.y() + y) * dim.z() + z; };
    std::vector<float> out(values.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, dim.x()), [&](const tbb::blocked_range<int>& r) {
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < dim.y(); ++y)
                for (int z = 0; z < dim.z(); ++z) {
                    float m = -std::numeric_limits<float>::max();
                    for (int i = std::max(0, x - 1); i <= std::min(dim.x() - 1, x + 1); ++i)
                        for (int j = std::max(0, y - 1); j <= std::min(dim.y() - 1, y + 1); ++j)
                            for (int k = std::max(0, z - 1); k <= std::min(dim.z() - 1, z + 1); ++k)
                                m = std::max(m, values[index(i, j, k)]);
                    out[index(x, y, z)] = m;
                }
    });
    return out;
}

std::vector<float> leafStretch(const std::vector<Vec3d>& ps, const std::vector<Vec3d>& pt,
                               const Coord& n, float tau, double spacing,
                               const std::vector<uint8_t>& known)
{
    auto index = [&n](int x, int y, int z) { return (size_t(x) * n.y() + y) * n.z() + z; };
    auto has = [&](const Coord& c) {
        return known.empty() || known[index(c.x(), c.y(), c.z())] != 0;
    };
    auto norm = [spacing](const Vec3d& dx, const Vec3d& dy, const Vec3d& dz) {
        return spectralNorm(dx, dy, dz) / spacing;
    };
    // The difference along `axis` between the neighbouring centres (one-sided at the box's faces
    // and beside centres not known).
    auto diff = [&](const std::vector<Vec3d>& p, int x, int y, int z, int axis) {
        Coord a(x, y, z), b(x, y, z);
        if (!has(a)) return Vec3d(0.0);
        b[axis] += 1;
        if (b[axis] >= n[axis] || !has(b)) {
            b = a;
            a[axis] -= 1;
            if (a[axis] < 0 || !has(a)) return Vec3d(0.0);
        }
        return p[index(b.x(), b.y(), b.z())] - p[index(a.x(), a.y(), a.z())];
    };
    std::vector<float> own(ps.size(), 1.0f);
    tbb::parallel_for(tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < n.y(); ++y)
                for (int z = 0; z < n.z(); ++z) {
                    const double s =
                        norm(diff(ps, x, y, z, 0), diff(ps, x, y, z, 1), diff(ps, x, y, z, 2));
                    const double t =
                        norm(diff(pt, x, y, z, 0), diff(pt, x, y, z, 1), diff(pt, x, y, z, 2));
                    own[index(x, y, z)] =
                        float(tau < 0.0f ? std::max(s, t) : (1.0 - tau) * s + tau * t);
                }
    });
    std::vector<float> stretch = neighbourhoodMax(own, n);
    for (float& g : stretch) g = std::max(1.0f, 1.25f * g);
    return stretch;
}

std::vector<uint8_t> CoarseBlocks::wanted(const Coord& n) const
{
    auto index = [&n](int x, int y, int z) { return (size_t(x) * n.y() + y) * n.z() + z; };
    std::vector<uint8_t> out(size_t(n.x()) * n.y() * n.z(), 0);
    constexpr int kApron = 2; // a leaf's stretch reads its neighbours', which read theirs
    for (int bx = 0; bx < dim.x(); ++bx)
        for (int by = 0; by < dim.y(); ++by)
            for (int bz = 0; bz < dim.z(); ++bz) {
                if (kind[(size_t(bx) * dim.y() + by) * dim.z() + bz] != 0) continue;
                const Coord lo(bx * kLeaves - kApron, by * kLeaves - kApron, bz * kLeaves - kApron);
                const Coord hi = lo + Coord(kLeaves - 1 + 2 * kApron);
                for (int x = std::max(0, lo.x()); x <= std::min(n.x() - 1, hi.x()); ++x)
                    for (int y = std::max(0, lo.y()); y <= std::min(n.y() - 1, hi.y()); ++y)
                        for (int z = std::max(0, lo.z()); z <= std::min(n.z() - 1, hi.z()); ++z)
                            out[index(x, y, z)] = 1;
            }
    return out;
}

} // namespace volmorph::detail
