#include <volmorph/PairSuggest.h>

#include <Eigen/Eigenvalues>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace volmorph {
namespace {

constexpr size_t kMaxPoints = 20000; ///< interior points kept per side (evenly strided)
/// Spreads (covariance eigenvalues) closer than this share of the largest are taken as equal.
constexpr double kIsotropic = 0.05;
constexpr double kTipReach =
    0.15; ///< the farthest a tip pair moves a tip past the box, per diagonal

/// One side: points inside it (density >= 0.5, world units), and the box of its principal axes.
struct Shape {
    std::vector<Vec3d> inside;
    double volume = 0.0; ///< of the interior, world units cubed
    Vec3d centroid{0.0};
    std::array<Vec3d, 3> axes; ///< unit, right-handed, the largest spread first
    Vec3d spread{0.0};         ///< the covariance's eigenvalues along axes, descending
    Vec3d origin{0.0}, scale{0.0};

    /// Whether two spreads are within kIsotropic of the largest: the axes across them are then
    /// the shape's by chance (a sphere's, a cylinder's about its axis), not its own.
    bool alike(int i, int j) const { return spread[i] - spread[j] < kIsotropic * spread[0]; }
    bool determined() const { return !alike(0, 1) && !alike(1, 2); }

    FeatureElement box() const { return FeatureElement{origin, axes[0], axes[1], axes[2], scale}; }

    /// p in the box's frame, each axis scaled to [-1, 1] across the box.
    Vec3d normalized(const Vec3d& p) const
    {
        const Vec3d d = p - origin;
        Vec3d u;
        for (int i = 0; i < 3; ++i) u[i] = d.dot(axes[i]) / (0.5 * scale[i]);
        return u;
    }
};

/// Calls f(coord) for every interior voxel of `density` (density >= 0.5, tiles voxel by voxel).
template <typename F>
void forEachInside(const openvdb::FloatGrid& density, F&& f)
{
    for (auto it = density.cbeginValueOn(); it; ++it) {
        if (*it < 0.5f) continue;
        if (it.isVoxelValue()) {
            f(it.getCoord());
            continue;
        }
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        for (auto c = box.begin(); c; ++c) f(*c);
    }
}

/// The interior points of `density`, every stride-th so that at most kMaxPoints are kept (nothing
/// else is stored: hero grids hold 10^8 interior voxels); `count` gets how many there are.
std::vector<Vec3d> insidePoints(const openvdb::FloatGrid& density, size_t& count)
{
    count = 0;
    forEachInside(density, [&](const openvdb::Coord&) { ++count; });
    const size_t stride = std::max<size_t>(1, count / kMaxPoints);
    std::vector<Vec3d> points;
    size_t index = 0;
    forEachInside(density, [&](const openvdb::Coord& c) {
        if (index++ % stride == 0) points.push_back(density.indexToWorld(c.asVec3d()));
    });
    return points;
}

Shape shapeOf(const openvdb::FloatGrid& density, double voxel)
{
    Shape s;
    size_t count = 0;
    s.inside = insidePoints(density, count);
    s.volume = double(count) * voxel * voxel * voxel;
    if (s.inside.empty()) throw std::invalid_argument("a side has no interior (density >= 0.5)");
    for (const Vec3d& p : s.inside) s.centroid += p;
    s.centroid /= double(s.inside.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const Vec3d& p : s.inside) {
        const Eigen::Vector3d d(p.x() - s.centroid.x(), p.y() - s.centroid.y(),
                                p.z() - s.centroid.z());
        covariance += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    const Eigen::Matrix3d v = solver.eigenvectors(); // ascending eigenvalues
    s.axes[0] = Vec3d(v(0, 2), v(1, 2), v(2, 2)).unit();
    s.axes[1] = Vec3d(v(0, 1), v(1, 1), v(2, 1)).unit();
    s.axes[2] = s.axes[0].cross(s.axes[1]).unit();
    const Eigen::Vector3d lambda = solver.eigenvalues();
    s.spread = Vec3d(lambda(2), lambda(1), lambda(0));
    return s;
}

/// The unit vector in the plane normal to `n` nearest one of `frame`'s axes (the one whose
/// projection is longest).
Vec3d nearestInPlane(const Vec3d& n, const std::array<Vec3d, 3>& frame)
{
    Vec3d best(0.0);
    for (const Vec3d& axis : frame) {
        const Vec3d p = axis - n * n.dot(axis);
        if (p.lengthSqr() > best.lengthSqr()) best = p;
    }
    return best.unit();
}

/// Where a's spreads are alike, the axes across them follow `lean` (the other side's, or the
/// world's) instead of the eigen solver's arbitrary choice: a sphere turned into a cube then
/// needs no turn.
void settleAxes(Shape& a, const std::array<Vec3d, 3>& lean)
{
    if (a.alike(0, 1) && a.alike(1, 2)) {
        a.axes = lean;
    } else if (a.alike(1, 2)) { // the longest axis is the shape's own
        a.axes[1] = nearestInPlane(a.axes[0], lean);
        a.axes[2] = a.axes[0].cross(a.axes[1]).unit();
    } else if (a.alike(0, 1)) { // the shortest is
        a.axes[0] = nearestInPlane(a.axes[2], lean);
        a.axes[1] = a.axes[2].cross(a.axes[0]).unit();
    }
}

/// The box spanning the shape's interior points along its axes.
void fitBox(Shape& s, double voxel)
{
    Vec3d lo(1e300), hi(-1e300);
    for (const Vec3d& p : s.inside)
        for (int i = 0; i < 3; ++i) {
            const double x = (p - s.centroid).dot(s.axes[i]);
            lo[i] = std::min(lo[i], x);
            hi[i] = std::max(hi[i], x);
        }
    s.origin = s.centroid;
    for (int i = 0; i < 3; ++i) {
        s.origin += s.axes[i] * (0.5 * (lo[i] + hi[i]));
        s.scale[i] = std::max(hi[i] - lo[i] + voxel, voxel); // voxel centres: half a voxel out
    }
}

/// The box pair's affine map from `from` to `to`.
Vec3d boxMap(const FeatureElement& from, const FeatureElement& to, const Vec3d& p)
{
    const Vec3d d = p - from.origin;
    const Vec3d fromAxes[3] = {from.xAxis, from.yAxis, from.zAxis};
    const Vec3d toAxes[3] = {to.xAxis, to.yAxis, to.zAxis};
    Vec3d q = to.origin;
    for (int i = 0; i < 3; ++i) q += toAxes[i] * (d.dot(fromAxes[i]) * to.scale[i] / from.scale[i]);
    return q;
}

/// The share of `from`'s interior points that the box map carries inside `density`.
double carriedInside(const Shape& from, const FeatureElement& fromBox, const FeatureElement& toBox,
                     const openvdb::FloatGrid& density)
{
    const auto accessor = density.getConstAccessor();
    size_t inside = 0;
    for (const Vec3d& p : from.inside) {
        const Vec3d q = density.worldToIndex(boxMap(fromBox, toBox, p));
        inside += openvdb::tools::BoxSampler::sample(accessor, q) >= 0.5f;
    }
    return double(inside) / double(from.inside.size());
}

/// The IoU of the source carried by the box map with the target (what the morph's source side
/// becomes at t = 1 with this one pair): the intersection estimated both ways (the share of each
/// side's points the map carries inside the other, times that side's volume where it lands).
double boxIoU(const Shape& s, const FeatureElement& sourceBox,
              const openvdb::FloatGrid& sourceDensity, const Shape& t,
              const FeatureElement& targetBox, const openvdb::FloatGrid& targetDensity)
{
    const double stretch = (targetBox.scale[0] * targetBox.scale[1] * targetBox.scale[2]) /
                           (sourceBox.scale[0] * sourceBox.scale[1] * sourceBox.scale[2]);
    const double carried = s.volume * stretch; // the source's volume once mapped
    const double common = 0.5 * (carriedInside(s, sourceBox, targetBox, targetDensity) * carried +
                                 carriedInside(t, targetBox, sourceBox, sourceDensity) * t.volume);
    return common / (carried + t.volume - common);
}

/// Each side's tips: the points farthest out in the box's normalized frame, each at least 60
/// degrees from the others seen from the centre; at most six.
std::vector<Vec3d> tipsOf(const Shape& s)
{
    std::vector<Vec3d> tips, directions;
    for (int k = 0; k < 6; ++k) {
        double best = 0.5; // beyond half the box
        const Vec3d* tip = nullptr;
        for (const Vec3d& p : s.inside) {
            const Vec3d u = s.normalized(p);
            const double r = u.length();
            if (r <= best) continue;
            const bool apart = std::all_of(directions.begin(), directions.end(),
                                           [&](const Vec3d& d) { return u.dot(d) < 0.5 * r; });
            if (!apart) continue;
            best = r;
            tip = &p;
        }
        if (!tip) break;
        tips.push_back(*tip);
        directions.push_back(s.normalized(*tip).unit());
    }
    return tips;
}

/// Point pairs at the tips: a source tip carried by the box map and a target tip that are each
/// other's nearest, closer than kTipReach of the target box's diagonal (a correction of the box
/// near its tips, not a jump) and farther than two voxels (else the box alone places it).
std::vector<FeaturePairSpec> tipPairs(const Shape& source, const FeatureElement& sourceBox,
                                      const Shape& target, const FeatureElement& targetBox,
                                      double voxel)
{
    const std::vector<Vec3d> a = tipsOf(source), b = tipsOf(target);
    std::vector<Vec3d> carried;
    for (const Vec3d& p : a) carried.push_back(boxMap(sourceBox, targetBox, p));
    auto nearest = [](const Vec3d& p, const std::vector<Vec3d>& among) {
        size_t index = 0;
        for (size_t j = 1; j < among.size(); ++j)
            if ((among[j] - p).lengthSqr() < (among[index] - p).lengthSqr()) index = j;
        return index;
    };
    const double reach = kTipReach * targetBox.scale.length();
    std::vector<FeaturePairSpec> pairs;
    for (size_t i = 0; i < a.size() && !b.empty(); ++i) {
        const size_t j = nearest(carried[i], b);
        const double apart = (carried[i] - b[j]).length();
        if (nearest(b[j], carried) != i || apart > reach || apart <= 2.0 * voxel) continue;
        // The box's frames and scales on both points: this pair's map is the box's, shifted to
        // carry the tip onto the tip, so that blending the two only bends the box's map locally.
        FeaturePairSpec pair;
        pair.type = FeatureType::Point;
        pair.source = sourceBox;
        pair.target = targetBox;
        pair.source.origin = a[i];
        pair.target.origin = b[j];
        pairs.push_back(pair);
    }
    return pairs;
}

} // namespace

PairSuggestion suggestPairs(const VolumeSet& source, const VolumeSet& target)
{
    const double voxel = source.density->voxelSize()[0];
    Shape s = shapeOf(*source.density, voxel), t = shapeOf(*target.density, voxel);
    const std::array<Vec3d, 3> world = {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)};
    const std::array<Vec3d, 3> sourceLean = t.determined() ? t.axes : world;
    const std::array<Vec3d, 3> targetLean = s.determined() ? s.axes : world;
    settleAxes(s, sourceLean);
    settleAxes(t, targetLean);
    fitBox(s, voxel);
    fitBox(t, voxel);
    PairSuggestion out;
    FeaturePairSpec box;
    box.type = FeatureType::Box;
    box.source = s.box();
    // The target's principal axes in any order and either sign, right-handed (24 frames): the one
    // whose box map carries the most of each side inside the other. (Signs alone are not enough
    // where the two shapes' longest axes differ.)
    out.boxOverlap = -1.0;
    const FeatureElement t0 = t.box();
    const Vec3d axes[3] = {t0.xAxis, t0.yAxis, t0.zAxis};
    for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) {
            if (x == y) continue;
            for (const auto& [sx, sy] :
                 {std::pair{1.0, 1.0}, {1.0, -1.0}, {-1.0, 1.0}, {-1.0, -1.0}}) {
                FeatureElement candidate = t0;
                candidate.xAxis = axes[x] * sx;
                candidate.yAxis = axes[y] * sy;
                candidate.zAxis = candidate.xAxis.cross(candidate.yAxis);
                candidate.scale = Vec3d(t0.scale[x], t0.scale[y], t0.scale[3 - x - y]);
                const double overlap =
                    boxIoU(s, box.source, *source.density, t, candidate, *target.density);
                if (overlap > out.boxOverlap) {
                    out.boxOverlap = overlap;
                    box.target = candidate;
                }
            }
        }
    out.pairs.push_back(box);
    for (FeaturePairSpec& p : tipPairs(s, box.source, t, box.target, voxel)) out.pairs.push_back(p);
    return out;
}

} // namespace volmorph
