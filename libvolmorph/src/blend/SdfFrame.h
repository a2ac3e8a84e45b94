// One sdf-mode frame: the blend of the two extended distances through their warps, evaluated
// only in the blocks that can hold its narrow band (BlockClasses.h), with colour on the band.
// SdfBlend.cpp then removes dust (Islands.h) and rebuilds the band (Redistance.h).
#pragma once

#include "blend/BlendTime.h"
#include "blend/BlockClasses.h"
#include "blend/ColorBlend.h"
#include "blend/ExtendedDistance.h"
#include "blend/IdentityDistances.h"
#include "blend/Redistance.h"
#include "warp/FrameWarp.h"

#include <volmorph/Voxelize.h>
#include <volmorph/Warp.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

namespace volmorph::detail {

inline constexpr float kSqrt3 = 1.7320508f;
/// The farthest a voxel of a 2^3 block can be from the mean of the block's voxels under a map
/// with Lipschitz constant 1: (3 + 3 sqrt(2) + sqrt(3)) / 8 voxels (a sum over the others).
inline constexpr float kBlockReach = 1.1222f;

template <typename Sampler>
class SdfFrame {
public:
    using ValueLeaf = openvdb::FloatTree::LeafNodeType;
    using ColorLeaf = openvdb::Vec3STree::LeafNodeType;

    /// sdfTime, colorTime: the distance's and the colour's schedules at each voxel (uniform
    /// without a timing).
    SdfFrame(const VolumeSet& source, const VolumeSet& target, const ExtendedDistance& farSource,
             const ExtendedDistance& farTarget, const FrameWarp& warp, const BlendTime& sdfTime,
             const BlendTime& colorTime, Vec3f background, double toleranceVoxels)
        : mSource(source), mTarget(target), mFarSource(farSource), mFarTarget(farTarget),
          mWarp(warp), mSdfTime(sdfTime), mColorTime(colorTime), mTau(sdfTime.atAll().tau),
          mTauColor(colorTime.atAll().tau), mBackground(background),
          mVoxel(float(source.voxelSize())),
          mWidth(std::min(source.sdf->background(), target.sdf->background()) / mVoxel),
          // The extended fields' slack, and the approximated warp's error: leaves are judged with
          // the exact warp at their centres, their voxels evaluated with the approximated one
          // (with no pairs both are the identity, exactly).
          mSlack(std::max(farSource.transitionError(), farTarget.transitionError()) + 0.5f +
                 (warp.pairCount() > 0 ? float(toleranceVoxels) : 0.0f))
    {
    }

    /// Classifies the leaves of `box`. With `prune` false every leaf is evaluated (the reference).
    /// `identity`: with no pairs, the distances kept across frames (for the leaves' centres).
    void classify(const openvdb::CoordBBox& box, bool prune, IdentityDistances* identity = nullptr)
    {
        BlockClasses& c = mClasses;
        c.leaves = box >> size_t(3);
        const openvdb::Coord n = c.leaves.dim();
        const size_t count = size_t(n.x()) * n.y() * n.z();
        const bool warped = mWarp.pairCount() > 0;
        // With pairs, blocks of leaves first: only the leaves near the band are warped one by one.
        // (Not under a timing: a block's tau varies more than its centre says.)
        const CoarseBlocks coarse =
            prune && warped && !identity && mSdfTime.uniform() ? coarseBlocks() : CoarseBlocks{};
        const std::vector<uint8_t> wanted =
            coarse.empty() ? std::vector<uint8_t>{} : coarse.wanted(n);
        std::vector<Vec3d> ps, pt; // the warped centres (with pairs)
        std::vector<float> apart;  // |d_T - d_S| at the centres, world units
        const std::vector<float> blend = identity ? keptCentreBlends(box, *identity, apart)
                                                  : centreBlends(ps, pt, wanted, apart);
        mSamples += wanted.empty() ? count : size_t(std::count(wanted.begin(), wanted.end(), 1));
        // The warp's stretch per leaf; the identity's is 1 exactly.
        std::vector<float> stretch =
            warped ? leafStretch(ps, pt, n, mSdfTime.uniform() ? mTau : -1.0f, 8.0, wanted)
                   : std::vector<float>(count, 1.0f);
        addTimingStretch(stretch, apart);
        c.maxStretch = 1.0;
        for (size_t i = 0; i < count; ++i)
            if (wanted.empty() || wanted[i])
                c.maxStretch = std::max(c.maxStretch, double(stretch[i]));
        // Values are computed within the compute band of each leaf: the band and one voxel more,
        // so that every band voxel's neighbours are known. A voxel of leaf L is in the band that
        // is kept when its value is within G_L width voxels of zero (G_L the leaf's stretch), and
        // its neighbours, in L or a face neighbour L', are then within G_L (width + 1) voxels, so
        // each leaf's compute band is (width + 1) voxels times the largest G of the leaf and its
        // 26 neighbours. (One band for the whole box, from the largest G anywhere, costs some two
        // times the samples where the warp stretches only some leaves.) A leaf can be skipped
        // when its centre is farther than its corners' reach plus that, plus a voxel for the
        // extended fields' transition.
        c.band = neighbourhoodMax(stretch, n);
        for (float& g : c.band) g *= (mWidth + 1.0f) * mVoxel;
        mComputeBand = float(c.maxStretch) * (mWidth + 1.0f) * mVoxel;
        c.kind.assign(count, 0);
        c.stretch = std::move(stretch);
        mPrune = prune;
        if (!prune) return;
        for (size_t i = 0; i < count; ++i)
            if (!(std::abs(blend[i]) < limit(c.stretch[i], 3.5f * kSqrt3, c.band[i])))
                c.kind[i] = blend[i] < 0.0f ? -1 : 1;
        if (!coarse.empty()) takeCoarse(coarse);
    }

    /// Beyond this blend (world units) at a point, no voxel within `reach` voxels of it is in the
    /// compute band `band` (of the leaf that holds them): G reach, plus the slack of the extended
    /// fields' transition (where they pass from the band to the coarse field, they may change by
    /// up to the coarse error more than a distance does).
    float limit(float stretch, float reach, float band) const
    {
        return (stretch * reach + mSlack) * mVoxel + band;
    }

    const BlockClasses& classes() const { return mClasses; }
    /// The widest compute band of the box (world units): beyond it, a value is outside every one.
    float computeBand() const { return mComputeBand; }
    /// The output band's half width, world units.
    float width() const { return mWidth * mVoxel; }
    /// The points where the blend was evaluated: centres classified and voxels filled.
    uint64_t samples() const { return mSamples; }
    /// Inactive values lie at least this many voxels from the zero set (compute band / G).
    int deepVoxels() const { return int(mWidth + 1.0f); }

    /// What a leaf's voxels turned out to be.
    struct Seen {
        bool on = false, inside = false, outside = false;
        /// -1 when every value is inside and none active, +1 when every value is outside and
        /// none active, 0 otherwise (keep the leaf).
        int whole() const
        {
            return on ? 0 : (inside && !outside ? -1 : (outside && !inside ? 1 : 0));
        }
    };

    /// Where a leaf's fill writes each side's distance (world units) at the voxels it blends
    /// (for the velocity, SdfVelocity.h); null: not kept.
    struct Distances {
        ValueLeaf* source = nullptr;
        ValueLeaf* target = nullptr;
        void record(openvdb::Index n, float da, float db) const
        {
            if (!source) return;
            source->setValueOn(n, da);
            target->setValueOn(n, db);
        }
    };

    /// The leaf's bands (world units): its compute band, and the band that is kept.
    struct Bands {
        float compute, keep;
    };
    Bands bandsAt(const openvdb::Coord& origin) const
    {
        const size_t i = mClasses.index(origin >> size_t(3));
        return {mClasses.band[i], mClasses.stretch[i] * mWidth * mVoxel};
    }

    /// Blends voxel n from its two distances: active within the compute band, +/- the band
    /// (inactive) beyond it; its colour, colorAt(), within the band that is kept.
    template <typename ColorAt>
    void blendVoxel(openvdb::Index n, float da, float db, float tau, const Bands& bands,
                    ValueLeaf& value, ColorLeaf& color, Seen& seen, const ColorAt& colorAt) const
    {
        const float d = (1.0f - tau) * da + tau * db;
        seen.inside = seen.inside || d < 0.0f;
        seen.outside = seen.outside || !(d < 0.0f);
        if (!(std::abs(d) < bands.compute)) {
            value.setValueOff(n, d < 0.0f ? -bands.compute : bands.compute);
            return;
        }
        value.setValueOn(n, d);
        seen.on = true;
        if (std::abs(d) < bands.keep) color.setValueOn(n, colorAt());
    }

    /// Fills one leaf: the blend within the compute band (active), +/- the compute band beyond
    /// (inactive); colour where the band may be. Returns -1 when every value is inside and none
    /// active, +1 when every value is outside and none active, 0 otherwise (keep the leaf).
    int operator()(const WarpLeaf& w, ValueLeaf& value, ColorLeaf& color,
                   const Distances& distances = {}) const
    {
        LeafFill fill(*this, w, value, color, distances);
        for (int q = 0; q < 8; ++q)
            fill.quarter((q & 1) * 4, ((q >> 1) & 1) * 4, ((q >> 2) & 1) * 4);
        mSamples += fill.samples;
        return fill.seen.whole();
    }

    /// Fills one leaf as operator() does, from the two distances at its voxels (the identity
    /// warp's points, cached across frames). Every voxel is blended: from distances at hand that is
    /// cheaper than judging quarters and blocks, and gives the same leaf (what those judgements
    /// skip is beyond the compute band, with their sign).
    int operator()(const openvdb::Coord& origin, const IdentityDistances::Leaf& distances,
                   ValueLeaf& value, ColorLeaf& color, const Distances& record = {}) const
    {
        ColorBlend<Sampler> colors(mSource, mTarget, mTauColor, mBackground);
        const float ramp = kSdfRampVoxels * mVoxel;
        Seen seen;
        const Bands bands = bandsAt(origin);
        for (openvdb::Index n = 0; n < 512; ++n) {
            const float da = distances.source[n], db = distances.target[n];
            record.record(n, da, db);
            const openvdb::Coord ijk = origin + value.offsetToLocalCoord(n);
            const Taus tau = tausAt(ijk.asVec3d());
            colors.setTau(tau.color);
            blendVoxel(n, da, db, tau.sdf, bands, value, color, seen,
                       [&] { return colors.atVoxel(ijk, fogRamp(da, ramp), fogRamp(db, ramp)); });
        }
        return seen.whole();
    }

    void addSamples(uint64_t n) const { mSamples += n; }

    /// The distance's and the colour's tau at output index point ijk.
    struct Taus {
        float sdf, color;
    };
    Taus tausAt(const Vec3d& ijk) const
    {
        if (mSdfTime.uniform()) return {mTau, mTauColor};
        const Delay delay = mSdfTime.delayAt(ijk);
        return {mSdfTime.fromDelay(delay).tau, mColorTime.fromDelay(delay).tau};
    }

    /// The kept band (world units) of the leaf at `origin`, or the widest one outside the box.
    float keepBandAt(const openvdb::Coord& origin) const
    {
        return mClasses.leaves.isInside(origin >> size_t(3)) ? bandsAt(origin).keep
                                                             : float(mClasses.maxStretch) * width();
    }

private:
    /// One leaf's fill through the warp. Each 4^3 quarter of the leaf is first judged by its
    /// voxel (2, 2, 2), at most 2 sqrt(3) voxels from the others, then each of its 2^3 blocks by
    /// the blend at the mean of its voxels' warped points: voxel v is within
    /// sum_u |p(v) - p(u)| / 8 <= G (3 + 3 sqrt(2) + sqrt(3)) / 8 of that mean. Beyond the limit
    /// a quarter or block is inside or outside as a whole. The rest is blended voxel by voxel.
    class LeafFill {
    public:
        LeafFill(const SdfFrame& f, const WarpLeaf& w, ValueLeaf& value, ColorLeaf& color,
                 const Distances& distances)
            : mF(f), mW(w), mValue(value), mColor(color), mDistances(distances), mA(f.mFarSource),
              mB(f.mFarTarget), mColors(f.mSource, f.mTarget, f.mTauColor, f.mBackground),
              // Each side's colour weight is its fog at the warped point, derived from its
              // distance with the output's ramp: what "empty there" means for a surface.
              mRamp(kSdfRampVoxels * f.mVoxel), mBands(f.bandsAt(w.origin))
        {
            const float stretch = f.mClasses.stretch[f.mClasses.index(w.origin >> size_t(3))];
            mQuarterLimit = f.limit(stretch, 2.0f * kSqrt3, mBands.compute);
            mBlockLimit = f.limit(stretch, kBlockReach, mBands.compute);
        }

        void quarter(int qx, int qy, int qz)
        {
            if (mF.mPrune) {
                const openvdb::Index c = ((qx + 2) * 8 + qy + 2) * 8 + qz + 2;
                const float d = blendAt(mW.source(c), mW.target(c),
                                        mF.tausAt(at(qx + 2.0, qy + 2.0, qz + 2.0)).sdf);
                if (!(std::abs(d) < mQuarterLimit)) return constant(qx, qy, qz, 4, d);
            }
            for (int bq = 0; bq < 8; ++bq)
                block(qx + (bq & 1) * 2, qy + ((bq >> 1) & 1) * 2, qz + ((bq >> 2) & 1) * 2);
        }

        Seen seen;
        uint64_t samples = 0;

    private:
        void block(int bx, int by, int bz)
        {
            if (mF.mPrune) {
                Vec3f ms(0.0f), mt(0.0f);
                for (int v = 0; v < 8; ++v) {
                    const openvdb::Index n = openvdb::Index(
                        ((bx + (v & 1)) * 8 + by + ((v >> 1) & 1)) * 8 + bz + (v >> 2));
                    ms += mW.source(n);
                    mt += mW.target(n);
                }
                const float d = blendAt(ms * 0.125f, mt * 0.125f,
                                        mF.tausAt(at(bx + 0.5, by + 0.5, bz + 0.5)).sdf);
                if (!(std::abs(d) < mBlockLimit)) return constant(bx, by, bz, 2, d);
            }
            for (int i = bx; i < bx + 2; ++i)
                for (int j = by; j < by + 2; ++j)
                    for (int k = bz; k < bz + 2; ++k) {
                        const openvdb::Index n = openvdb::Index((i * 8 + j) * 8 + k);
                        const openvdb::Vec3R ps(mW.source(n)), pt(mW.target(n));
                        const float da = mA(ps), db = mB(pt);
                        ++samples;
                        mDistances.record(n, da, db);
                        const Taus tau = mF.tausAt(at(i, j, k));
                        mColors.setTau(tau.color);
                        mF.blendVoxel(n, da, db, tau.sdf, mBands, mValue, mColor, seen, [&] {
                            return mColors(ps, pt, fogRamp(da, mRamp), fogRamp(db, mRamp));
                        });
                    }
        }

        /// The blend at one pair of warped points (index space) by `tau`, counted as a sample.
        float blendAt(const Vec3f& ps, const Vec3f& pt, float tau)
        {
            ++samples;
            return (1.0f - tau) * mA(openvdb::Vec3R(ps)) + tau * mB(openvdb::Vec3R(pt));
        }

        /// The output index point at the leaf's local (x, y, z).
        Vec3d at(double x, double y, double z) const
        {
            return mW.origin.asVec3d() + Vec3d(x, y, z);
        }

        /// The cube of `size` voxels at (x0, y0, z0) of the leaf is inside or outside as a whole.
        void constant(int x0, int y0, int z0, int size, float d)
        {
            const float v = d < 0.0f ? -mBands.compute : mBands.compute;
            for (int i = x0; i < x0 + size; ++i)
                for (int j = y0; j < y0 + size; ++j)
                    for (int k = z0; k < z0 + size; ++k)
                        mValue.setValueOff(openvdb::Index((i * 8 + j) * 8 + k), v);
            (d < 0.0f ? seen.inside : seen.outside) = true;
        }

        const SdfFrame& mF;
        const WarpLeaf& mW;
        ValueLeaf& mValue;
        ColorLeaf& mColor;
        const Distances& mDistances;
        typename ExtendedDistance::template Reader<Sampler> mA, mB;
        ColorBlend<Sampler> mColors;
        float mRamp;
        Bands mBands;
        float mQuarterLimit = 0.0f, mBlockLimit = 0.0f;
    };

    /// The coarse pass (BlockClasses.h) over the box's leaves.
    CoarseBlocks coarseBlocks() const
    {
        constexpr int K = CoarseBlocks::kLeaves;
        const openvdb::Coord n = mClasses.leaves.dim(), first = mClasses.leaves.min();
        CoarseBlocks out;
        out.dim = openvdb::Coord((n.x() + K - 1) / K, (n.y() + K - 1) / K, (n.z() + K - 1) / K);
        const openvdb::Coord d = out.dim;
        const size_t count = size_t(d.x()) * d.y() * d.z();
        std::vector<Vec3d> ps(count), pt(count);
        std::vector<float> blend(count);
        const double half = 4.0 * K - 0.5; // from a block's first voxel to its centre
        tbb::parallel_for(tbb::blocked_range<int>(0, d.x()), [&](const tbb::blocked_range<int>& r) {
            typename ExtendedDistance::template Reader<Sampler> a(mFarSource), b(mFarTarget);
            for (int x = r.begin(); x != r.end(); ++x)
                for (int y = 0; y < d.y(); ++y)
                    for (int z = 0; z < d.z(); ++z) {
                        const size_t i = (size_t(x) * d.y() + y) * d.z() + z;
                        const openvdb::Coord leaf = first.offsetBy(x * K, y * K, z * K);
                        const Vec3d centre = leaf.asVec3d() * 8.0 + Vec3d(half);
                        mWarp.map(centre, ps[i], pt[i]);
                        blend[i] = (1.0f - mTau) * a(ps[i]) + mTau * b(pt[i]);
                    }
        });
        mSamples += count;
        out.stretch = leafStretch(ps, pt, d, mTau, 8.0 * K);
        for (float& g : out.stretch) g *= CoarseBlocks::kSafety;
        out.band = neighbourhoodMax(out.stretch, d);
        for (float& g : out.band) g *= (mWidth + 1.0f) * mVoxel;
        out.kind.assign(count, 0);
        const float reach = float(half) * kSqrt3; // from the centre to a corner voxel
        for (size_t i = 0; i < count; ++i)
            if (!(std::abs(blend[i]) < limit(out.stretch[i], reach, out.band[i])))
                out.kind[i] = blend[i] < 0.0f ? -1 : 1;
        return out;
    }

    /// The leaves of blocks the coarse pass judged whole take their block's sign.
    void takeCoarse(const CoarseBlocks& coarse)
    {
        BlockClasses& c = mClasses;
        const openvdb::Coord n = c.leaves.dim();
        for (int x = 0; x < n.x(); ++x)
            for (int y = 0; y < n.y(); ++y)
                for (int z = 0; z < n.z(); ++z) {
                    const size_t b = coarse.of(openvdb::Coord(x, y, z));
                    if (coarse.kind[b] == 0) continue;
                    const size_t i = (size_t(x) * n.y() + y) * n.z() + z;
                    c.kind[i] = coarse.kind[b];
                    c.stretch[i] = coarse.stretch[b];
                    c.band[i] = coarse.band[b];
                }
    }

    /// The blend at the centres of the classified box's leaves (`wanted`, unless empty, says which)
    /// through the exact warp, and the warped centres (index space) into ps and pt.
    std::vector<float> centreBlends(std::vector<Vec3d>& ps, std::vector<Vec3d>& pt,
                                    const std::vector<uint8_t>& wanted,
                                    std::vector<float>& apart) const
    {
        const BlockClasses& c = mClasses;
        const openvdb::Coord n = c.leaves.dim();
        auto index = [&n](int x, int y, int z) { return (size_t(x) * n.y() + y) * n.z() + z; };
        const size_t count = size_t(n.x()) * n.y() * n.z();
        std::vector<float> blend(count);
        apart.assign(count, 0.0f);
        ps.resize(count);
        pt.resize(count);
        tbb::parallel_for(tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
            typename ExtendedDistance::template Reader<Sampler> a(mFarSource), b(mFarTarget);
            for (int x = r.begin(); x != r.end(); ++x)
                for (int y = 0; y < n.y(); ++y)
                    for (int z = 0; z < n.z(); ++z) {
                        const size_t i = index(x, y, z);
                        if (!wanted.empty() && !wanted[i]) continue;
                        const openvdb::Coord leaf = c.leaves.min().offsetBy(x, y, z);
                        const Vec3d centre(leaf.x() * 8 + 3.5, leaf.y() * 8 + 3.5,
                                           leaf.z() * 8 + 3.5);
                        mWarp.map(centre, ps[i], pt[i]);
                        const float da = a(ps[i]), db = b(pt[i]), tau = tausAt(centre).sdf;
                        blend[i] = (1.0f - tau) * da + tau * db;
                        apart[i] = std::abs(db - da);
                    }
        });
        return blend;
    }

    /// The same from the distances kept across frames (the identity warp).
    std::vector<float> keptCentreBlends(const openvdb::CoordBBox& box, IdentityDistances& identity,
                                        std::vector<float>& apart) const
    {
        const auto centres = identity.centres<Sampler>(box, mFarSource, mFarTarget);
        std::vector<float> blend(centres->source.size());
        apart.resize(blend.size());
        const openvdb::CoordBBox& leaves = mClasses.leaves;
        const openvdb::Coord n = leaves.dim();
        for (size_t i = 0; i < blend.size(); ++i) {
            float tau = mTau;
            if (!mSdfTime.uniform()) {
                const int z = int(i % size_t(n.z())), y = int(i / size_t(n.z()) % size_t(n.y())),
                          x = int(i / (size_t(n.z()) * size_t(n.y())));
                const openvdb::Coord leaf = leaves.min().offsetBy(x, y, z);
                tau = tausAt(leaf.asVec3d() * 8.0 + Vec3d(3.5)).sdf;
            }
            const float da = centres->source[i], db = centres->target[i];
            blend[i] = (1.0f - tau) * da + tau * db;
            apart[i] = std::abs(db - da);
        }
        return blend;
    }

    /// With a timing, tau varies over a leaf, and the blend with it: |grad phi| <= G + |grad tau|
    /// |d_T - d_S| per voxel, where |d_T - d_S| is at most its value at the centre plus 2 G per
    /// voxel out to the leaf's corners (3.5 sqrt(3) voxels), and |grad tau| at most the timing's
    /// bound (0 where tau is clamped over the whole leaf: not begun, or done). The leaf's stretch
    /// becomes that bound: its bands and limits widen with it.
    void addTimingStretch(std::vector<float>& stretch, const std::vector<float>& apart) const
    {
        const float g = mSdfTime.maxGradient();
        if (g == 0.0f) return;
        const openvdb::Coord n = mClasses.leaves.dim();
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, stretch.size()),
            [&](const tbb::blocked_range<size_t>& r) {
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    const openvdb::Coord leaf = mClasses.leaves.min().offsetBy(
                        int(i / (size_t(n.y()) * n.z())), int(i / size_t(n.z()) % size_t(n.y())),
                        int(i % size_t(n.z())));
                    const Vec3d centre = leaf.asVec3d() * 8.0 + Vec3d(3.5);
                    if (mSdfTime.clampedNear(centre, 3.5 * kSqrt3)) continue;
                    stretch[i] += g * (apart[i] / mVoxel + 2.0f * stretch[i] * 3.5f * kSqrt3);
                }
            });
    }

    const VolumeSet& mSource;
    const VolumeSet& mTarget;
    const ExtendedDistance& mFarSource;
    const ExtendedDistance& mFarTarget;
    const FrameWarp& mWarp;
    const BlendTime& mSdfTime;
    const BlendTime& mColorTime;
    float mTau, mTauColor; ///< without a timing, every voxel's
    Vec3f mBackground;
    float mVoxel;              ///< world units
    float mWidth;              ///< the output band's half width, voxels
    float mSlack;              ///< voxels
    float mComputeBand = 0.0f; ///< the widest compute band (world units)
    bool mPrune = true;
    BlockClasses mClasses;
    mutable std::atomic<uint64_t> mSamples{0};
};

} // namespace volmorph::detail
