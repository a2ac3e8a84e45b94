// A signed distance field (world units) defined far beyond its narrow band, so that the sdf
// blend of two sides is a distance blend everywhere and not only where both bands overlap.
//
// A narrow band clamps distances to +/- its width, and the blend of two clamped values,
// (1 - tau)(-w) + tau(+w), changes sign at tau = 1/2 everywhere at once: every voxel inside one
// object and a few voxels outside the other would flip in one frame (the shape snaps instead of
// morphing). So both fields are extended, once per morph, over the box of source and target
// together plus a margin: the band's own values within kNear voxels of the surface, beyond kFar
// voxels the extended field, and a smoothstep between the two.
//
// The extended field has two parts, so that its cost grows with the surface, not the box:
// - a shell, kShellCells lattice cells (kShell voxels apart) thick around the band: OpenVDB's fast
//   sweeping over the band's dilation (tools::dilateSdf), seeded with the band's exact values at
//   the lattice points that fall in it (every surface has lattice points within sqrt(3) voxels;
//   the band is 3 voxels wide). It is read within kShellUse voxels of the surface.
// - beyond, a dense lattice kFarSpacing voxels apart over the box (a 512th of its voxels), swept
//   from the shell's values (tools::maskSdf).
// Fast sweeping is first order: 0.5 to 1 voxel off 30 voxels from a sphere, 5 voxels 200 voxels
// out on the far lattice. So each lattice point's distance is then taken to a point of the
// surface: in the shell, one step along the swept gradient and one along the band's, p - phi
// grad phi; on the far lattice, the surface point carried out along the characteristics by
// OpenVDB's extension (tools::sdfToExt) and brought back onto the surface the same way. The
// direction's error moves that point sideways, which changes a distance only to second order.
// A carried point is a point of the surface but not always the nearest (where characteristics
// cross, at a medial axis), so each lattice point then takes the nearest of its neighbours' too,
// a few passes (closest-point propagation, as jump flooding does): never under the distance. A read
// beyond the box (a warped point may leave it) is the distance to the nearest lattice point's
// surface point, not that point's value. Its accuracy against a sphere's closed form and against
// exact distances of real meshes is in BENCHMARKS.md (tests/bench/far_field_accuracy.cpp measures
// it); the largest errors sit at medial axes and cone points, which no lattice 8 voxels apart
// follows.
// Near the surface the band's own values are read: within kNear voxels, blended to kFar.
#pragma once

#include "blend/Abandonable.h"
#include "blend/Sample.h"

#include <volmorph/core/Interrupter.h>

#include <openvdb/openvdb.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

namespace volmorph::detail {

class ExtendedDistance {
public:
    static constexpr int kShell = 2, kShellCells = 24, kFarSpacing = 8;
    static constexpr int kSharePasses = 4;      ///< of shareFeet over the far lattice
    static constexpr int kShellSharePasses = 1; ///< of shareShellFeet over the shell
    /// The shell is read within kShellUse voxels of the surface, alone within kShellBlend.
    static constexpr float kShellBlend = 32.0f, kShellUse = 40.0f; // under kShell * kShellCells
    static constexpr float kNear = 2.0f, kFar = 2.9f;              // voxels

    /// The box the sdf blend extends both sides' fields over (index space): the objects' box and
    /// a margin for warped points that leave it, an eighth of its size, at least 8 voxels. With
    /// no pairs the points are the output's voxels: the blend's zero set lies within the objects'
    /// box (the bands' active voxels), and 8 voxels more hold its compute band. A read beyond the
    /// box measures to the nearest far lattice point's surface point (farAt).
    static openvdb::CoordBBox boxFor(const openvdb::FloatGrid& sourceBand,
                                     const openvdb::FloatGrid& targetBand, size_t pairCount);

    /// `band`: a level set; `box`: where to extend it (its index space). An empty box extends
    /// nothing: reads are the band's. A stop request from `interrupter` is answered at once
    /// (Interrupted): OpenVDB 10's fast sweeping takes no interrupter (about a second at 320
    /// voxels across), so the work runs abandonable (Abandonable.h); once abandoned, volmorph's
    /// own loops in it stop it early, between and within the steps.
    static std::unique_ptr<const ExtendedDistance>
    make(openvdb::FloatGrid::ConstPtr band, const openvdb::CoordBBox& box, Interrupter* interrupter)
    {
        return abandonable(
            [band, box](Interrupter& stop) {
                return std::make_unique<const ExtendedDistance>(band, box, stop);
            },
            interrupter);
    }

    /// What make() runs, on the work's own thread: `stop` is Abandonable's, never the caller's.
    ExtendedDistance(openvdb::FloatGrid::ConstPtr band, const openvdb::CoordBBox& box,
                     Interrupter& stop);

    /// The largest difference between the extended field and the band where the extended field
    /// is used, voxels.
    float transitionError() const { return mTransitionError; }

    /// Trilinear read of the dense far lattice at p (fine index space), world units. Beyond the
    /// box, the distance to the surface point of the lattice point nearest p: a warped point can
    /// leave the box, and the nearest face's value would be short by as far as it left it.
    /// Written out rather than tools::BoxSampler over a tree: this read is among the frame's
    /// hottest.
    float farAt(const openvdb::Vec3R& p) const
    {
        const DenseField& d = mFarField;
        int i[3];
        float f[3];
        bool inside = true;
        for (int k = 0; k < 3; ++k) {
            const double u = p[k] * (1.0 / kFarSpacing) - d.origin[k];
            const double c = std::clamp(u, 0.0, double(d.dim[k] - 1));
            inside = inside && c == u;
            i[k] = std::min(int(c), std::max(d.dim[k] - 2, 0));
            f[k] = float(c - i[k]);
        }
        if (!inside) { // the lattice point nearest p
            const size_t n =
                d.index(i[0] + (f[0] > 0.5f), i[1] + (f[1] > 0.5f), i[2] + (f[2] > 0.5f));
            const openvdb::Vec3s& foot = d.feet[n];
            if (foot.x() != kNoFoot)
                return std::copysign(float((p - openvdb::Vec3R(foot)).length()) * mVoxel,
                                     d.values[n]);
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
              mSkipFine((kFar + d.mExtendedError + 0.5f) * d.mVoxel)
        {
        }
        /// The extended field alone at p (fine index space), world units.
        float extended(const openvdb::Vec3R& p)
        {
            // Within kShellUse of the surface all 8 lattice points around p lie in the shell;
            // beyond the shell its values are +/- far more (flood filled), so a read that mixes
            // them is never under kShellUse. From kShellBlend on, the far lattice takes over
            // smoothly: the two differ by the far lattice's error, a step in the blend otherwise.
            const float g = shellAt(p * (1.0 / kShell));
            const float a = std::abs(g) / mD.mVoxel;
            if (a <= kShellBlend) return g;
            const float far = mD.farAt(p);
            if (a >= kShellUse) return far;
            const float x = (a - kShellBlend) / (kShellUse - kShellBlend),
                        s = x * x * (3.0f - 2.0f * x);
            return g + s * (far - g);
        }
        /// The distance at p (fine index space), world units.
        float operator()(const openvdb::Vec3R& p)
        {
            if (mD.mBlockIndex.empty()) return sample<Sampler>(mFine, p);
            // |extended - band| <= the measured error (plus half a voxel between lattice
            // points), so a value this far out means the band's value is beyond kFar too.
            const float g = extended(p);
            if (std::abs(g) >= mSkipFine) return g;
            const float f = sample<Sampler>(mFine, p);
            const float a = std::abs(f) / mD.mVoxel;
            if (a <= kNear) return f;
            if (a >= kFar) return g;
            const float x = (a - kNear) / (kFar - kNear), s = x * x * (3.0f - 2.0f * x);
            return f + s * (g - f);
        }

    private:
        /// Trilinear read of the shell at q (its index space); outside the shell a value beyond
        /// kShellUse.
        float shellAt(const openvdb::Vec3R& q)
        {
            const openvdb::Coord ijk = openvdb::Coord::floor(q);
            const openvdb::Coord block(ijk.x() >> 3, ijk.y() >> 3, ijk.z() >> 3);
            if (block != mBlock || !mValues) {
                mBlock = block;
                mValues = mD.block(block);
            }
            if (!mValues) return kOutside;
            const int x = ijk.x() & 7, y = ijk.y() & 7, z = ijk.z() & 7;
            const float* v = mValues + (x * kApron + y) * kApron + z;
            const float fx = float(q.x() - ijk.x()), fy = float(q.y() - ijk.y()),
                        fz = float(q.z() - ijk.z());
            constexpr int sx = kApron * kApron, sy = kApron;
            auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
            const float x00 = lerp(v[0], v[sx], fx), x10 = lerp(v[sy], v[sx + sy], fx);
            const float x01 = lerp(v[1], v[sx + 1], fx), x11 = lerp(v[sy + 1], v[sx + sy + 1], fx);
            return lerp(lerp(x00, x10, fy), lerp(x01, x11, fy), fz);
        }

        const ExtendedDistance& mD;
        openvdb::FloatGrid::ConstAccessor mFine;
        float mSkipFine;
        openvdb::Coord mBlock{std::numeric_limits<int>::max()};
        const float* mValues = nullptr;
    };

private:
    /// The shell is kept as blocks of 8^3 lattice cells, each with the next block's first layer
    /// on its three upper faces, so that a trilinear read never leaves its block: one lookup for
    /// every read, where OpenVDB's leaves need eight for the reads that straddle two (a third of
    /// them), in the frame's hottest read.
    static constexpr int kApron = 9;
    static constexpr float kOutside = 1.0e30f;
    const float* block(const openvdb::Coord& b) const
    {
        const auto it = mBlockIndex.find(b);
        return it == mBlockIndex.end()
                   ? nullptr
                   : mBlocks.data() + size_t(it->second) * kApron * kApron * kApron;
    }
    /// The shell's swept distances replaced by distances to surface points (see the .cpp).
    void toSurfacePoints(openvdb::FloatTree& shell, Interrupter* interrupter) const;
    /// One pass over the shell's surface points (one per lattice point, kNoFoot where none):
    /// each takes the nearest of its own and its 26 neighbours'.
    void shareShellFeet(openvdb::tree::LeafManager<openvdb::Vec3STree>& leaves) const;
    /// The shell's blocks, from its tree.
    void makeBlocks(const openvdb::FloatTree& shell);

    /// The far lattice, dense over its box.
    struct DenseField {
        std::vector<float> values;        ///< x-major
        std::vector<openvdb::Vec3s> feet; ///< each point's surface point (fine index space), or
                                          ///< kNoFoot
        openvdb::Coord origin, dim;       ///< the box, far lattice index space

        size_t index(int x, int y, int z) const { return (size_t(x) * dim.y() + y) * dim.z() + z; }
    };

    /// The shell's seeds: the band's values at the lattice points (kShell apart) that fall in it,
    /// signed flood filled.
    openvdb::FloatGrid::Ptr shellSeeds() const;
    /// The far lattice's seeds over `far` (its index space): the shell's values where it holds
    /// them, the band's sign elsewhere.
    openvdb::FloatGrid::Ptr farSeeds(const openvdb::CoordBBox& far,
                                     const openvdb::FloatTree& shell) const;
    /// The far lattice over `far` into mFarField: the distance to `feet` (the surface point each
    /// lattice point was carried, the band's index space; kNoFoot where none was), brought back
    /// onto the surface through `shell` and the band, signed by `wide`; or `wide` itself.
    static constexpr float kNoFoot = 1.0e30f;
    void makeDense(const openvdb::FloatGrid& wide, const openvdb::Vec3SGrid& feet,
                   const openvdb::FloatTree& shell, const openvdb::CoordBBox& far);
    /// One pass over the far lattice: each point takes the nearest of its own and its 26
    /// neighbours' surface points (see the .cpp).
    void shareFeet();
    /// mExtendedError and mTransitionError, over the band's voxels.
    void measureErrors();

    openvdb::FloatGrid::ConstPtr mBand;
    std::unordered_map<openvdb::Coord, uint32_t> mBlockIndex; ///< empty: not extended
    std::vector<float> mBlocks; ///< kApron^3 values per block, x-major
    DenseField mFarField;
    float mExtendedError = 0.0f;   ///< max |extended - band| over the band's voxels, voxels
    float mTransitionError = 0.0f; ///< the same where |band| >= kNear
    float mVoxel = 1.0f;
};

} // namespace volmorph::detail
