#include "warp/adaptive/PairColumns.h"

#include <algorithm>
#include <cmath>

namespace volmorph::detail {
namespace {

/// Frobenius norm of the difference of two affine maps' linear parts (bounds the operator norm).
double linearDistance(const InverseWarp::Affine& a, const InverseWarp::Affine& b)
{
    return std::sqrt((a.col[0] - b.col[0]).lengthSqr() + (a.col[1] - b.col[1]).lengthSqr() +
                     (a.col[2] - b.col[2]).lengthSqr());
}

} // namespace

template <class Real>
PairColumns<Real>::PairColumns(const InverseWarp& warp,
                               const std::vector<InverseWarp::Affine> maps[2])
{
    const size_t n = warp.pairCount();
    padded = (n + 7) / 8 * 8;
    groups.resize(padded / kLanes);
    InverseWarp::Affine zero;
    zero.col[0] = zero.col[1] = zero.col[2] = zero.offset = Vec3d(0.0);
    for (size_t i = 0; i < padded; ++i) {
        // Padding: a point at the origin with zero maps.
        const Feature e = i < n ? warp.interpolated(i) : Feature();
        const int extent = e.type == FeatureType::Point       ? 0
                           : e.type == FeatureType::Segment   ? 1
                           : e.type == FeatureType::Rectangle ? 2
                                                              : 3;
        const Vec3d* axes[3] = {&e.x, &e.y, &e.z};
        auto set = [&](int c, double v) { groups[i / kLanes].v[c][i % kLanes] = Real(v); };
        for (int k = 0; k < 3; ++k) {
            set(Origin + k, e.origin[k]);
            for (int a = 0; a < 3; ++a) set(Axis + 3 * k + a, (*axes[k])[a]);
            set(Half + k, k < extent ? 0.5 * e.scale[k] : 0.0);
            const Vec3d& ax = *axes[k];
            set(Reach + k, 0.5 * (std::abs(ax.x()) + std::abs(ax.y()) + std::abs(ax.z())));
        }
        set(Box, e.type == FeatureType::Box ? 1 : 0);
        set(Live, i < n ? 1 : 0);
        for (int side = 0; side < 2; ++side) {
            const InverseWarp::Affine& m = i < n ? maps[side][i] : zero;
            for (int a = 0; a < 3; ++a) {
                for (int k = 0; k < 3; ++k) set(Affine + 12 * side + 3 * k + a, m.col[k][a]);
                set(Affine + 12 * side + 9 + a, m.offset[a]);
            }
        }
    }
}

template struct PairColumns<double>;
template struct PairColumns<float>;

WarpColumns::WarpColumns(const InverseWarp& warp, const std::vector<InverseWarp::Affine> maps[2])
    : exact(warp, maps), bound(warp, maps)
{
    const size_t n = warp.pairCount(), padded = bound.padded;
    const std::vector<InverseWarp::Affine>& source = maps[0];
    const std::vector<InverseWarp::Affine>& target = maps[1];
    slope.assign(n * padded, 0.0f);
    for (size_t j = 0; j < n; ++j)
        for (size_t i = 0; i < n; ++i)
            slope[j * padded + i] = float(std::max(linearDistance(source[i], source[j]),
                                                   linearDistance(target[i], target[j])));
}

} // namespace volmorph::detail
