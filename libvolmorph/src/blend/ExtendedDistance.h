// A signed distance field (world units) defined far beyond its narrow band, so that the sdf
// blend of two sides is a distance blend everywhere and not only where both bands overlap.
//
// A narrow band clamps distances to +/- its width, and the blend of two clamped values,
// (1 - tau)(-w) + tau(+w), changes sign at tau = 1/2 everywhere at once: every voxel inside one
// object and a few voxels outside the other would flip in one frame (the shape snaps instead of
// morphing). So both fields are extended, once per morph, over the box of source and target
// together plus a margin: the band's own values within kNear voxels of the surface, beyond kFar
// voxels a coarse field (kCoarse voxels apart) filled in by OpenVDB's fast sweeping
// (tools::maskSdf), and a smoothstep between the two.
//
// The coarse lattice takes the band's exact values where its points fall in the band (every
// surface has lattice points within sqrt(3) voxels; the band is 3 voxels wide) and the band's sign
// elsewhere; maskSdf then fills in the distances (to first order: the closed-form test of
// concentric spheres measures 0.36 voxel at most in the blended band). Its error near the surface
// is larger, which the transition hides: within kNear voxels the value is the band's. A coarser
// lattice (4 voxels) was tried: 5 times cheaper to build, but 0.6 voxel off in that test.
#pragma once

#include "blend/Sample.h"

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace volmorph::detail {

class ExtendedDistance {
public:
    static constexpr int kCoarse = 2;
    static constexpr float kNear = 2.0f, kFar = 2.9f; // voxels

    /// `band`: a level set; `box`: where to extend it (its index space). An empty box extends
    /// nothing: reads are the band's.
    ExtendedDistance(openvdb::FloatGrid::ConstPtr band, const openvdb::CoordBBox& box);

    /// The largest difference between the coarse field and the band where the coarse field is
    /// used, voxels.
    float transitionError() const { return mTransitionError; }

    /// Trilinear read of the coarse field at p (fine index space), world units. Beyond the box the
    /// nearest face's values hold (distances there are far outside anyway). Written out rather
    /// than tools::BoxSampler over the dense field: in this, the frame's hottest read, the
    /// sampler's eight separate lookups cost about a tenth of the sdf-mode frame.
    float coarseAt(const openvdb::Vec3R& p) const
    {
        const DenseField& d = mCoarse;
        int i[3];
        float f[3];
        for (int k = 0; k < 3; ++k) {
            const double c =
                std::clamp(p[k] * (1.0 / kCoarse) - d.origin[k], 0.0, double(d.dim[k] - 1));
            i[k] = std::min(int(c), std::max(d.dim[k] - 2, 0));
            f[k] = float(c - i[k]);
        }
        const size_t sz = d.dim.z() > 1 ? 1 : 0, sy = d.dim.y() > 1 ? size_t(d.dim.z()) : 0,
                     sx = d.dim.x() > 1 ? size_t(d.dim.y()) * d.dim.z() : 0;
        const float* v = d.values.data() + d.index(i[0], i[1], i[2]);
        auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
        const float x00 = lerp(v[0], v[sx], f[0]), x10 = lerp(v[sy], v[sx + sy], f[0]);
        const float x01 = lerp(v[sz], v[sx + sz], f[0]),
                    x11 = lerp(v[sy + sz], v[sx + sy + sz], f[0]);
        return lerp(lerp(x00, x10, f[1]), lerp(x01, x11, f[1]), f[2]);
    }

    /// One thread's view.
    template <typename Sampler>
    class Reader {
    public:
        explicit Reader(const ExtendedDistance& d)
            : mD(d), mFine(d.mBand->getConstAccessor()),
              mSkipFine((kFar + d.mCoarseError + 0.5f) * d.mVoxel)
        {
        }
        /// The distance at p (fine index space), world units.
        float operator()(const openvdb::Vec3R& p)
        {
            if (mD.mCoarse.values.empty()) return sample<Sampler>(mFine, p);
            // |coarse - band| <= the measured error (plus half a voxel between lattice points), so
            // a coarse value this far out means the band's value is beyond kFar too.
            const float g = mD.coarseAt(p);
            if (std::abs(g) >= mSkipFine) return g;
            const float f = sample<Sampler>(mFine, p);
            const float a = std::abs(f) / mD.mVoxel;
            if (a <= kNear) return f;
            if (a >= kFar) return g;
            const float x = (a - kNear) / (kFar - kNear), s = x * x * (3.0f - 2.0f * x);
            return f + s * (g - f);
        }

    private:
        const ExtendedDistance& mD;
        openvdb::FloatGrid::ConstAccessor mFine;
        float mSkipFine;
    };

private:
    /// The coarse field, dense over its box.
    struct DenseField {
        std::vector<float> values;  ///< x-major
        openvdb::Coord origin, dim; ///< the box, coarse index space

        size_t index(int x, int y, int z) const { return (size_t(x) * dim.y() + y) * dim.z() + z; }
    };

    /// The coarse lattice's seeds over `coarse` (coarse index space): the band's values where
    /// lattice points fall in it, its sign elsewhere.
    openvdb::FloatGrid::Ptr seeds(const openvdb::CoordBBox& coarse) const;
    /// Copies `wide` over `coarse` into mCoarse.
    void makeDense(const openvdb::FloatGrid& wide, const openvdb::CoordBBox& coarse);
    /// mCoarseError and mTransitionError, over the band's voxels.
    void measureErrors();

    openvdb::FloatGrid::ConstPtr mBand;
    DenseField mCoarse;            ///< the extended coarse field over its box
    float mCoarseError = 0.0f;     ///< max |coarse - band| over the band's voxels, voxels
    float mTransitionError = 0.0f; ///< the same where |band| >= kNear
    float mVoxel = 1.0f;
};

} // namespace volmorph::detail
