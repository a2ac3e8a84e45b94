// Shadows: the transmittance from a point of the volume toward each light, precomputed once per
// image: a deep shadow map (Lokovic and Veach 2000) of parallel rays for a directional light, of
// rays leaving the light for a point light. Both are built in parallel and stop early when
// interrupted.
#pragma once

#include <volmorph/render/Renderer.h>

#include "GridReaders.h"
#include "PointShadowMap.h"
#include "ShadowColumns.h"

#include <openvdb/util/NullInterrupter.h>

#include <memory>
#include <vector>

namespace volmorph::render {

/// Optical depth (index units times sigma) from world point p along `direction` for up to
/// `distance` world units, integrated cell by cell.
double opticalDepth(Intersector& inter, bool levelSet, DensityReader& acc, const Vec3d& p,
                    const Vec3d& direction, double distance, double sigmaPerVoxel);

/// Transmittance toward a directional light: a deep shadow map (Lokovic and Veach). A lattice of
/// columns parallel to the light, `spacing` world units apart, each marched once through the
/// volume cell by cell, keeping the transmittance every `spacing` along it; looked up by bilinear
/// interpolation across columns and linear along them.
class ShadowMap {
public:
    /// `travel`: the way the light travels. Columns are skipped once the interrupter asks to stop
    /// (the map is then incomplete: the caller checks the interrupter and discards it).
    ShadowMap(const MarchInputs& in, const Vec3d& travel, double spacing);

    /// Transmittance toward the light at index point ip of the density grid.
    double lookup(const Vec3d& ip) const
    {
        double a, b, c;
        if (mLinear) {
            a = mRow[0].dot(ip) + mOffset.x();
            b = mRow[1].dot(ip) + mOffset.y();
            c = mRow[2].dot(ip) + mOffset.z();
        } else {
            const Vec3d p = mDensity.indexToWorld(ip);
            a = (p.dot(mU) - mOrigin.x()) / mSpacing;
            b = (p.dot(mV) - mOrigin.y()) / mSpacing;
            c = (p.dot(mW) - mOrigin.z()) / mSpacing;
        }
        return mColumns->across(0, mCount[0], mCount[1], a, b, c);
    }

private:
    /// The light's frame, the lattice's origin, size and index-space map; returns the columns'
    /// length in world units.
    double placeLattice(const openvdb::FloatGrid& density, const openvdb::BoolGrid& mask,
                        const Vec3d& travel);

    const openvdb::FloatGrid& mDensity;
    Vec3d mU, mV, mW, mOrigin; ///< light frame; origin in its coordinates (world units)
    double mSpacing;
    bool mLinear = false;
    Vec3d mRow[3], mOffset; ///< index space to lattice coordinates, for a linear transform
    int mCount[2];
    std::unique_ptr<ShadowColumns> mColumns;
};

/// One light's shadow: a deep shadow map, parallel for a directional light, around a point light.
struct Shadow {
    std::unique_ptr<ShadowMap> map;
    std::unique_ptr<PointShadowMap> point;
};

/// The shadows of every light, in the order of `lights`; spacing `shadowCacheVoxels` voxels.
/// Returns early (with incomplete shadows) once `interrupter` asks to stop: the caller checks it.
std::vector<Shadow> buildShadows(const MarchInputs& in, const std::vector<Light>& lights,
                                 int shadowCacheVoxels);

} // namespace volmorph::render
