// Transmittance toward a point light: a deep shadow map around it (Lokovic and Veach 2000, as for a
// spot light). Rays leave the light through the lattice points of a cube's six faces, a cube map,
// each marched once through the volume (ShadowColumns), keeping the transmittance every `spacing`
// world units of distance from the light. A lookup takes the four rays around the point's
// direction, each at the point's distance, bilinearly. The lattice is fine enough that neighbouring
// rays are at most `spacing` apart across the occupied region, and only the rays that can meet it
// are marched: the cost grows with the region's cross-section seen from the light, as for a
// directional light's map, not with its volume.
#pragma once

#include "ShadowColumns.h"

#include <cmath>
#include <memory>

namespace volmorph::render {

class PointShadowMap {
public:
    /// `light`: the light's world position. Rays are skipped once the interrupter asks to stop
    /// (the map is then incomplete: the caller checks the interrupter and discards it).
    PointShadowMap(const MarchInputs& in, const Vec3d& light, double spacing);

    /// Transmittance toward the light at index point ip of the density grid.
    double lookup(const Vec3d& ip) const
    {
        const Vec3d dw = world(ip) - mLight;
        const Vec3d d(dw.dot(mAxes[0]), dw.dot(mAxes[1]), dw.dot(mAxes[2]));
        const Vec3d m(std::abs(d.x()), std::abs(d.y()), std::abs(d.z()));
        const int axis = m.x() >= m.y() ? (m.x() >= m.z() ? 0 : 2) : (m.y() >= m.z() ? 1 : 2);
        const double major = m[axis];
        if (!(major > 0.0)) return 1.0; // the light itself
        const Face& f = mFaces[2 * axis + (d[axis] < 0.0 ? 1 : 0)];
        const double a = (d[(axis + 1) % 3] / major + 1.0) * mHalf - f.i0,
                     b = (d[(axis + 2) % 3] / major + 1.0) * mHalf - f.j0;
        return mColumns->across(f.first, f.width, f.height, a, b, dw.length() / mSpacing);
    }

    /// Lattice points along a face's edge (the face has (resolution + 1)^2).
    int resolution() const { return mRes; }
    size_t rays() const { return mRays; }

private:
    /// The rays marched through one face: the lattice points (i0 .. i0 + width - 1, j0 .. j0 +
    /// height - 1), row by row from ray `first` on. Face 2a + s looks along axis a, toward + for s
    /// = 0, toward - for s = 1; its lattice coordinates are axes a + 1 and a + 2 (mod 3), over the
    /// major one's magnitude, from -1 to 1.
    struct Face {
        int i0 = 0, j0 = 0, width = 0, height = 0;
        size_t first = 0;
    };

    Vec3d world(const Vec3d& ip) const
    {
        return mLinear ? mW0 + mEx * ip.x() + mEy * ip.y() + mEz * ip.z()
                       : mDensity.indexToWorld(ip);
    }
    /// The cube's axes, the faces' rectangles of rays and the lattice's resolution; returns the
    /// rays' length.
    double placeFaces(const openvdb::BoolGrid& mask);
    /// The unit direction of ray c.
    Vec3d direction(size_t c) const;

    const openvdb::FloatGrid& mDensity;
    Vec3d mLight;
    /// The cube's axes (world): the third points at the occupied region's centre, so that the
    /// region is seen around a face's centre, where the lattice is even (toward a face's corner
    /// it is up to 5 times denser).
    Vec3d mAxes[3];
    double mSpacing;
    int mRes = 2;
    double mHalf = 1.0; ///< mRes / 2: lattice points per unit of face coordinate
    bool mLinear = false;
    Vec3d mW0, mEx, mEy, mEz; ///< index space to world, for a linear transform
    Face mFaces[6];
    size_t mRays = 0;
    std::unique_ptr<ShadowColumns> mColumns;
};

} // namespace volmorph::render
