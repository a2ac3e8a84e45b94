#include "PointShadowMap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace volmorph::render {

namespace {

/// At most this many rays (a light close to a large volume gets a coarser lattice).
constexpr double kMaxRays = double(1 << 24);

/// The face coordinates (a_lo, b_lo, a_hi, b_hi) of the rays through the face looking along +z
/// that meet a convex region with these corners (relative to the light, in the cube's frame), when
/// that face alone sees it; nothing otherwise.
std::optional<std::array<double, 4>> frontBounds(const std::array<Vec3d, 8>& corners)
{
    std::array<double, 4> box{1.0, 1.0, -1.0, -1.0};
    for (const Vec3d& c : corners) {
        if (!(c.z() > 0.0)) return std::nullopt;
        const double a = c.x() / c.z(), b = c.y() / c.z();
        if (std::abs(a) > 1.0 || std::abs(b) > 1.0) return std::nullopt;
        box = {std::min(box[0], a), std::min(box[1], b), std::max(box[2], a), std::max(box[3], b)};
    }
    return box;
}

} // namespace

PointShadowMap::PointShadowMap(const MarchInputs& in, const Vec3d& light, double spacing)
    : mDensity(in.density), mLight(light), mSpacing(spacing)
{
    mLinear = in.density.transform().isLinear();
    if (mLinear) {
        mW0 = in.density.indexToWorld(Vec3d(0.0));
        mEx = in.density.indexToWorld(Vec3d(1, 0, 0)) - mW0;
        mEy = in.density.indexToWorld(Vec3d(0, 1, 0)) - mW0;
        mEz = in.density.indexToWorld(Vec3d(0, 0, 1)) - mW0;
    }
    const double length = placeFaces(in.mask);
    mColumns = std::make_unique<ShadowColumns>(
        in, mRays,
        [this](size_t c, Vec3d& start, Vec3d& dir) {
            start = mLight;
            dir = direction(c);
        },
        length, spacing, 0.0);
}

double PointShadowMap::placeFaces(const openvdb::BoolGrid& mask)
{
    // The occupied region's box, one voxel wider, relative to the light (world units), in the
    // cube's frame.
    const openvdb::CoordBBox box = mask.evalActiveVoxelBoundingBox();
    const Vec3d centre = mDensity.indexToWorld(box.getCenter()) - mLight;
    mAxes[2] = centre.length() > 0.0 ? centre.unit() : Vec3d(0, 0, 1);
    mAxes[0] =
        (std::abs(mAxes[2].x()) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0)).cross(mAxes[2]).unit();
    mAxes[1] = mAxes[2].cross(mAxes[0]);
    std::array<Vec3d, 8> corners = occupiedCorners(mDensity, mask);
    double reach = 0.0;
    for (Vec3d& corner : corners) {
        const Vec3d w = corner - mLight;
        corner = Vec3d(w.dot(mAxes[0]), w.dot(mAxes[1]), w.dot(mAxes[2]));
        reach = std::max(reach, w.length());
    }
    // The region's directions from the light project onto the front face's square (a convex
    // region's projection is its corners' hull); or, for a light close to it or inside it, every
    // face is marched whole.
    std::array<std::array<double, 4>, 6> bounds;
    bounds.fill({1.0, 1.0, -1.0, -1.0});
    if (const auto front = frontBounds(corners))
        bounds[4] = *front;
    else
        bounds.fill({-1.0, -1.0, 1.0, 1.0});
    double area = 0.0; // of the faces' rectangles, in units of a whole face
    for (const auto& b : bounds)
        if (b[0] <= b[2] && b[1] <= b[3]) area += (b[2] - b[0]) * (b[3] - b[1]) / 4.0;
    // Neighbouring rays are at most 2 / mRes radians apart: `spacing` at the farthest corner.
    const double wanted = std::ceil(2.0 * reach / mSpacing);
    const double affordable = area > 0.0 ? std::sqrt(kMaxRays / area) : wanted;
    mRes = int(std::clamp(std::min(wanted, affordable), 2.0, double(1 << 20)));
    mHalf = 0.5 * mRes;
    for (int f = 0; f < 6; ++f) {
        const auto& b = bounds[size_t(f)];
        Face& face = mFaces[f];
        face.first = mRays;
        if (!(b[0] <= b[2] && b[1] <= b[3])) continue;
        auto lattice = [this](double x, bool up) {
            const double i = (x + 1.0) * mHalf;
            return std::clamp(int(up ? std::ceil(i) : std::floor(i)) + (up ? 1 : -1), 0, mRes);
        };
        face.i0 = lattice(b[0], false);
        face.j0 = lattice(b[1], false);
        face.width = lattice(b[2], true) - face.i0 + 1;
        face.height = lattice(b[3], true) - face.j0 + 1;
        mRays += size_t(face.width) * size_t(face.height);
    }
    return reach + 2.0 * mSpacing;
}

Vec3d PointShadowMap::direction(size_t c) const
{
    int f = 5;
    while (f > 0 && c < mFaces[f].first) --f;
    const Face& face = mFaces[f];
    const size_t local = c - face.first;
    const int i = face.i0 + int(local % size_t(face.width)),
              j = face.j0 + int(local / size_t(face.width));
    const int axis = f / 2;
    Vec3d d;
    d[axis] = f % 2 ? -1.0 : 1.0;
    d[(axis + 1) % 3] = i / mHalf - 1.0;
    d[(axis + 2) % 3] = j / mHalf - 1.0;
    return (mAxes[0] * d.x() + mAxes[1] * d.y() + mAxes[2] * d.z()).unit();
}

} // namespace volmorph::render
