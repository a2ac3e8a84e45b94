#include "Shadows.h"

#include "CellWalk.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::render {

using openvdb::FloatGrid;

/// Optical depth (index units times sigma) from world point p along `direction` for up to
/// `distance` world units, integrated cell by cell.
double opticalDepth(Intersector& inter, bool levelSet, DensityReader& acc, const Vec3d& p,
                    const Vec3d& direction, double distance, double sigmaPerVoxel)
{
    if (!inter.setWorldRay(VdbRay(p, direction, 0.0, distance))) return 0.0;
    Medium1D ray{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0), levelSet};
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    while (inter.march(t0, t1)) {
        const bool going = walkCells(acc, ray, t0, t1, [&](const Cell& cell, double ta, double tb) {
            tau += sigmaPerVoxel * ray.mass(cell, ta, tb);
            return tau <= kMaxOpticalDepth + 2.0;
        });
        if (!going) break;
    }
    return tau;
}

ShadowMap::ShadowMap(const MarchInputs& in, const Vec3d& travel, double spacing)
    : mDensity(in.density), mSpacing(spacing)
{
    const double length = placeLattice(in.density, in.mask, travel);
    mColumns = std::make_unique<ShadowColumns>(
        in, size_t(mCount[0]) * size_t(mCount[1]),
        [this](size_t c, Vec3d& start, Vec3d& direction) {
            const int i = int(c % size_t(mCount[0])), j = int(c / size_t(mCount[0]));
            start = mU * (mOrigin.x() + i * mSpacing) + mV * (mOrigin.y() + j * mSpacing) +
                    mW * mOrigin.z();
            direction = mW;
        },
        length, spacing, std::numeric_limits<double>::infinity());
}

double ShadowMap::placeLattice(const FloatGrid& density, const openvdb::BoolGrid& mask,
                               const Vec3d& travel)
{
    mW = travel.unit();
    mU = (std::abs(mW.x()) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0)).cross(mW).unit();
    mV = mW.cross(mU);
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const Vec3d& w : occupiedCorners(density, mask)) {
        const Vec3d l(w.dot(mU), w.dot(mV), w.dot(mW));
        lo = openvdb::math::minComponent(lo, l);
        hi = openvdb::math::maxComponent(hi, l);
    }
    mOrigin = lo - Vec3d(mSpacing);
    // For a linear transform, the lattice coordinates are an affine function of index space.
    mLinear = density.transform().isLinear();
    if (mLinear) {
        const Vec3d w0 = density.indexToWorld(Vec3d(0.0));
        const Vec3d ex = density.indexToWorld(Vec3d(1, 0, 0)) - w0,
                    ey = density.indexToWorld(Vec3d(0, 1, 0)) - w0,
                    ez = density.indexToWorld(Vec3d(0, 0, 1)) - w0;
        const Vec3d* axes[3] = {&mU, &mV, &mW};
        for (int r = 0; r < 3; ++r) {
            mRow[r] = Vec3d(ex.dot(*axes[r]), ey.dot(*axes[r]), ez.dot(*axes[r])) / mSpacing;
            mOffset[r] = (w0.dot(*axes[r]) - mOrigin[r]) / mSpacing;
        }
    }
    mCount[0] = int(std::ceil((hi.x() - mOrigin.x()) / mSpacing)) + 2;
    mCount[1] = int(std::ceil((hi.y() - mOrigin.y()) / mSpacing)) + 2;
    return hi.z() - mOrigin.z() + 2.0 * mSpacing;
}

std::vector<Shadow> buildShadows(const MarchInputs& in, const std::vector<Light>& lights,
                                 int shadowCacheVoxels)
{
    std::vector<Shadow> shadows(lights.size());
    if (shadowCacheVoxels <= 0) return shadows; // exact transmittance per sample: nothing to build
    const double spacing = in.density.voxelSize()[0] * shadowCacheVoxels;
    for (size_t l = 0; l < lights.size(); ++l) {
        if (in.interrupter && in.interrupter->wasInterrupted()) break;
        if (lights[l].type == Light::Type::Directional)
            shadows[l].map = std::make_unique<ShadowMap>(in, lights[l].direction, spacing);
        else if (lights[l].type == Light::Type::Point)
            shadows[l].point = std::make_unique<PointShadowMap>(in, lights[l].position, spacing);
    }
    return shadows;
}

} // namespace volmorph::render
