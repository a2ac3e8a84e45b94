// sdf mode with no feature pairs: both extended distances at the output voxels, kept per leaf
// across frames.
#pragma once

#include "blend/ExtendedDistance.h"

#include <openvdb/openvdb.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace volmorph::detail {

/// With no feature pairs the warp is the identity at every t, so the two extended distances at a
/// voxel are the same in every frame; only the blend's weight changes. This keeps them per output
/// leaf, computed the first time a frame needs the leaf, for the frames after it. The values are
/// the ones a frame would sample itself (the same reads at the same points), so frames are the
/// same bit for bit with or without the cache. Safe for frames made at once on several threads:
/// a leaf computed twice at the same time is kept once. Beyond `maxLeaves` cached leaves, or
/// outside its box, leaves are computed and not kept.
class IdentityDistances {
public:
    struct Leaf {
        float source[512], target[512]; ///< world units, OpenVDB's voxel order
    };

    /// `box`: output index space, the leaves to keep.
    IdentityDistances(const openvdb::CoordBBox& box, size_t maxLeaves)
        : mLeaves(box >> size_t(3)), mMax(maxLeaves)
    {
        if (!box.empty()) {
            const size_t n = size_t(mLeaves.dim().x()) * mLeaves.dim().y() * mLeaves.dim().z();
            mSlots = std::make_unique<std::atomic<Leaf*>[]>(n);
            for (size_t i = 0; i < n; ++i) mSlots[i].store(nullptr, std::memory_order_relaxed);
            mSlotCount = n;
        }
    }
    ~IdentityDistances()
    {
        for (size_t i = 0; i < mSlotCount; ++i) delete mSlots[i].load(std::memory_order_relaxed);
    }
    IdentityDistances(const IdentityDistances&) = delete;
    IdentityDistances& operator=(const IdentityDistances&) = delete;

    /// The distances at the voxels of the leaf at `origin`: the kept ones, or computed with `a`
    /// and `b` (into `scratch` when they are not to be kept). `computed` counts the samples taken.
    template <typename Sampler>
    const Leaf& get(const openvdb::Coord& origin, ExtendedDistance::Reader<Sampler>& a,
                    ExtendedDistance::Reader<Sampler>& b, Leaf& scratch, uint64_t& computed)
    {
        const openvdb::Coord leaf = origin >> 3;
        std::atomic<Leaf*>* slot = nullptr;
        if (mSlotCount && mLeaves.isInside(leaf)) {
            const openvdb::Coord d = leaf - mLeaves.min(), n = mLeaves.dim();
            slot = &mSlots[(size_t(d.x()) * n.y() + d.y()) * n.z() + d.z()];
            if (const Leaf* kept = slot->load(std::memory_order_acquire)) return *kept;
        }
        const bool keep = slot && mCount.load(std::memory_order_relaxed) < mMax;
        std::unique_ptr<Leaf> fresh = keep ? std::make_unique<Leaf>() : nullptr;
        Leaf& out = keep ? *fresh : scratch;
        for (int i = 0; i < 8; ++i)
            for (int j = 0; j < 8; ++j)
                for (int k = 0; k < 8; ++k) {
                    // The point as the identity warp gives it (single precision, as WarpLeaf holds
                    // it).
                    const openvdb::Vec3R p(
                        Vec3f(float(origin.x() + i), float(origin.y() + j), float(origin.z() + k)));
                    const int n = (i * 8 + j) * 8 + k;
                    out.source[n] = a(p);
                    out.target[n] = b(p);
                }
        computed += 1024;
        if (!keep) return out;
        Leaf* expected = nullptr;
        if (slot->compare_exchange_strong(expected, fresh.get(), std::memory_order_acq_rel)) {
            mCount.fetch_add(1, std::memory_order_relaxed);
            return *fresh.release();
        }
        return *expected; // another frame kept the same values first
    }

    /// The distances at the centres of the leaves of `box` (output index space), x-major over
    /// box >> 3: what SdfFrame::classify() samples first in every frame. Computed by the first
    /// frame that asks for this box.
    struct Centres {
        openvdb::CoordBBox box;
        std::vector<float> source, target;
    };
    template <typename Sampler>
    std::shared_ptr<const Centres> centres(const openvdb::CoordBBox& box,
                                           const ExtendedDistance& farSource,
                                           const ExtendedDistance& farTarget)
    {
        {
            std::lock_guard<std::mutex> lock(mCentresMutex);
            if (mCentres && mCentres->box == box) return mCentres;
        }
        auto c = std::make_shared<Centres>();
        c->box = box;
        const openvdb::CoordBBox leaves = box >> size_t(3);
        const openvdb::Coord n = leaves.dim();
        c->source.resize(size_t(n.x()) * n.y() * n.z());
        c->target.resize(c->source.size());
        tbb::parallel_for(tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
            ExtendedDistance::Reader<Sampler> a(farSource), b(farTarget);
            for (int x = r.begin(); x != r.end(); ++x)
                for (int y = 0; y < n.y(); ++y)
                    for (int z = 0; z < n.z(); ++z) {
                        const openvdb::Coord leaf = leaves.min().offsetBy(x, y, z);
                        const openvdb::Vec3R centre(leaf.x() * 8 + 3.5, leaf.y() * 8 + 3.5,
                                                    leaf.z() * 8 + 3.5);
                        const size_t i = (size_t(x) * n.y() + y) * n.z() + z;
                        c->source[i] = a(centre);
                        c->target[i] = b(centre);
                    }
        });
        std::lock_guard<std::mutex> lock(mCentresMutex);
        if (!mCentres) mCentres = c;
        return c;
    }

private:
    openvdb::CoordBBox mLeaves; ///< leaf coordinates (index >> 3)
    std::mutex mCentresMutex;
    std::shared_ptr<const Centres> mCentres;
    size_t mMax;
    size_t mSlotCount = 0;
    std::unique_ptr<std::atomic<Leaf*>[]> mSlots;
    std::atomic<size_t> mCount{0};
};

} // namespace volmorph::detail
