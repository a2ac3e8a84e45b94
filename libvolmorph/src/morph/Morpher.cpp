// Domain, warp, resample, blend. One of the few translation units with OpenVDB's tools headers.
#include <volmorph/Morph.h>
#include <volmorph/Warp.h>

#include "Stretch.h"
#include "warp/AdaptiveWarp.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/math/Mat3.h>
#include <openvdb/util/Util.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <type_traits>
#include <cstdio>

namespace volmorph {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatTree;
using openvdb::Vec3STree;

/// Densities at or below this are empty (a trilinear sample at the edge of a fog's support).
constexpr float kEmpty = 1e-6f;

/// sdf mode: the fog rises from 0 to 1 across this many voxels around the surface.
constexpr float kSdfRampVoxels = 1.5f;

constexpr float kSqrt3 = 1.7320508f;
/// The farthest a voxel of a 2^3 block can be from the mean of the block's voxels under a map
/// with Lipschitz constant 1: (3 + 3 sqrt(2) + sqrt(3)) / 8 voxels (a sum over the others).
constexpr float kBlockReach = 1.1222f;

/// The box of the 8 corners of `box` under p -> M^-1 (p - b), M and b of `a`.
CoordBBox inverseImage(const InverseWarp::Affine& a, const CoordBBox& box)
{
    const openvdb::math::Mat3d m(a.col[0], a.col[1], a.col[2], /*rows=*/false);
    const openvdb::math::Mat3d inv = m.inverse();
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int k = 0; k < 8; ++k) {
        const Vec3d p((k & 1) ? box.max().x() : box.min().x(),
                      (k & 2) ? box.max().y() : box.min().y(),
                      (k & 4) ? box.max().z() : box.min().z());
        const Vec3d d = p - a.offset;
        const Vec3d q(inv(0, 0) * d.x() + inv(0, 1) * d.y() + inv(0, 2) * d.z(),
                      inv(1, 0) * d.x() + inv(1, 1) * d.y() + inv(1, 2) * d.z(),
                      inv(2, 0) * d.x() + inv(2, 1) * d.y() + inv(2, 2) * d.z());
        lo = minComponent(lo, q);
        hi = maxComponent(hi, q);
    }
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e8, 1.0e8)); };
    return CoordBBox(Coord(clampInt(std::floor(lo.x())), clampInt(std::floor(lo.y())),
                           clampInt(std::floor(lo.z()))),
                     Coord(clampInt(std::ceil(hi.x())), clampInt(std::ceil(hi.y())),
                           clampInt(std::ceil(hi.z()))));
}

/// Removes dust from the blended field before its band is rebuilt: face-connected pieces of the
/// interior (values < 0) with fewer than `minVoxels` voxels, apart from the largest, become outside
/// (`outside`); bubbles, pieces of the exterior with fewer than `minVoxels` voxels enclosed by the
/// interior (no face neighbour in the background), become inside (-`outside`). Returns the count.
///
/// Active values are those within `outside` of zero; every inactive negative value (a voxel or a
/// tile) lies at least `depth` voxels inside, so its piece holds the lattice ball of that radius.
/// When `minVoxels` is at most that ball's count, only the active voxels need segmenting (the deep
/// interior would cost the most), and a small piece is large after all when a face neighbour is
/// deep inside.
size_t dropIslands(openvdb::FloatGrid& values, int minVoxels, float outside, int depth)
{
    if (minVoxels <= 0) return 0;
    int ball = 0;
    for (int x = -depth; x <= depth; ++x)
        for (int y = -depth; y <= depth; ++y)
            for (int z = -depth; z <= depth; ++z) ball += x * x + y * y + z * z <= depth * depth;
    const bool deepIsLarge = minVoxels <= ball;
    bool anyDeep = false;
    // Interior: negative values (every one, or the active ones); exterior candidates: positive
    // active values (the far exterior is background).
    auto pieces = [&](bool negative) {
        openvdb::BoolTree::Ptr mask;
        if (negative && !deepIsLarge) {
            mask = openvdb::tools::sdfInteriorMask(values, 0.0f)->treePtr();
        } else {
            mask =
                std::make_shared<openvdb::BoolTree>(values.tree(), false, openvdb::TopologyCopy());
            openvdb::tree::LeafManager<openvdb::BoolTree> leaves(*mask);
            leaves.foreach ([&values, negative](openvdb::BoolTree::LeafNodeType& leaf, size_t) {
                const auto* source = values.tree().probeConstLeaf(leaf.origin());
                if (!source) return;
                const float* v = source->buffer().data();
                openvdb::BoolTree::LeafNodeType::NodeMaskType sign; // on where negative
                for (openvdb::Index n = 0; n < openvdb::BoolTree::LeafNodeType::SIZE; ++n)
                    if (v[n] < 0.0f) sign.setOn(n);
                leaf.setValueMask(leaf.getValueMask() & (negative ? sign : !sign));
            });
            if (negative)
                for (auto it = values.tree().cbeginValueOff(); it && !anyDeep; ++it)
                    anyDeep = *it < 0.0f;
        }
        std::vector<openvdb::BoolTree::Ptr> out;
        openvdb::tools::segmentActiveVoxels(*mask, out); // largest first
        return out;
    };
    size_t changed = 0;
    auto acc = values.getAccessor();
    auto set = [&acc](const openvdb::BoolTree& piece, float value) {
        for (auto it = piece.cbeginValueOn(); it; ++it)
            for (auto c = it.getBoundingBox().begin(); c; ++c) acc.setValue(*c, value);
    };
    auto touchesDeep = [&](const openvdb::BoolTree& piece) {
        for (auto it = piece.cbeginValueOn(); it; ++it)
            for (int k = 0; k < 6; ++k) { // the face neighbours
                const openvdb::Coord n = it.getCoord() + openvdb::util::COORD_OFFSETS[k];
                if (!acc.isValueOn(n) && acc.getValue(n) < 0.0f) return true;
            }
        return false;
    };
    // Both segmentations at once (each is partly serial); the exterior's again only when
    // removing islands changed the values it was taken from.
    std::vector<openvdb::BoolTree::Ptr> islands, gaps;
    tbb::parallel_invoke([&] { islands = pieces(true); }, [&] { gaps = pieces(false); });
    for (size_t i = anyDeep ? 0 : 1; i < islands.size(); ++i)
        if (islands[i]->activeVoxelCount() < openvdb::Index64(minVoxels) &&
            !(anyDeep && touchesDeep(*islands[i]))) {
            set(*islands[i], outside);
            ++changed;
        }
    if (changed > 0) gaps = pieces(false);
    for (const openvdb::BoolTree::Ptr& gap : gaps) {
        if (gap->activeVoxelCount() >= openvdb::Index64(minVoxels)) continue;
        bool enclosed = true;
        for (auto it = gap->cbeginValueOn(); it && enclosed; ++it)
            for (auto c = it.getBoundingBox().begin(); c && enclosed; ++c)
                for (int k = 0; k < 6 && enclosed; ++k) {
                    // A face neighbour that is positive and inactive is the far exterior.
                    const openvdb::Coord n = *c + openvdb::util::COORD_OFFSETS[k];
                    enclosed = acc.isValueOn(n) || acc.getValue(n) < 0.0f;
                }
        if (enclosed) {
            set(*gap, -outside);
            ++changed;
        }
    }
    return changed;
}

/// Sampler::sample(acc, p). For BoxSampler, when the 2^3 values it reads lie in one leaf (7 of
/// every 8 positions per axis), they are read from that leaf's buffer, or are one tile's value,
/// instead of by eight accessor lookups; the interpolation is still BoxSampler's own, so the
/// result is the same bit for bit. This read is the sdf-mode frame's hottest.
template <typename Sampler, typename Accessor>
typename Accessor::ValueType sample(Accessor& acc, const openvdb::Vec3R& p)
{
    if constexpr (std::is_same_v<Sampler, openvdb::tools::BoxSampler>) {
        const Coord ijk = Coord::floor(p);
        if ((ijk.x() & 7) != 7 && (ijk.y() & 7) != 7 && (ijk.z() & 7) != 7) {
            using Value = typename Accessor::ValueType;
            Value data[2][2][2];
            if (const auto* leaf = acc.probeConstLeaf(ijk)) {
                const openvdb::Index o = leaf->coordToOffset(ijk);
                for (openvdb::Index i = 0; i < 2; ++i)
                    for (openvdb::Index j = 0; j < 2; ++j)
                        for (openvdb::Index k = 0; k < 2; ++k)
                            data[i][j][k] = leaf->getValue(o + (i << 6) + (j << 3) + k);
            } else {
                const Value v = acc.getValue(ijk); // a tile or the background: one value for all 8
                for (auto& plane : data)
                    for (auto& row : plane) row[0] = row[1] = v;
            }
            return openvdb::tools::BoxSampler::trilinearInterpolation(data, p - ijk.asVec3d());
        }
    }
    return Sampler::sample(acc, p);
}

/// Colour weighted by each side's density (premultiplied), so an empty side contributes no colour.
template <typename Sampler>
struct ColorBlend {
    openvdb::Vec3SGrid::ConstAccessor cs, ct;
    float tau;
    Vec3f background;

    ColorBlend(const VolumeSet& source, const VolumeSet& target, float tauColor, const Vec3f& bg)
        : cs(source.color->getConstAccessor()), ct(target.color->getConstAccessor()), tau(tauColor),
          background(bg)
    {
    }
    /// ps, pt: the warped points; a, b: the densities there.
    Vec3f operator()(const openvdb::Vec3R& ps, const openvdb::Vec3R& pt, float a, float b)
    {
        return mix(
            a, b, [&] { return Vec3f(sample<Sampler>(cs, ps)); },
            [&] { return Vec3f(sample<Sampler>(ct, pt)); });
    }
    /// The same at voxel ijk of both sides (the identity warp). Trilinear weights there are 1 and
    /// 0, so BoxSampler's value is the voxel's own: read it directly.
    Vec3f atVoxel(const Coord& ijk, float a, float b)
    {
        if constexpr (!std::is_same_v<Sampler, openvdb::tools::BoxSampler>) {
            const openvdb::Vec3R p(Vec3f(float(ijk.x()), float(ijk.y()), float(ijk.z())));
            return (*this)(p, p, a, b);
        } else {
            return mix(
                a, b, [&] { return cs.getValue(ijk); }, [&] { return ct.getValue(ijk); });
        }
    }

private:
    /// The density-weighted mix; each side's colour is read only when its weight is positive.
    template <typename ReadS, typename ReadT>
    Vec3f mix(float a, float b, const ReadS& readSource, const ReadT& readTarget) const
    {
        const float wa = (1.0f - tau) * std::max(a, 0.0f), wb = tau * std::max(b, 0.0f);
        if (!(wa + wb > 0.0f)) return background;
        const Vec3f ca = wa > 0.0f ? readSource() : Vec3f(0.0f);
        const Vec3f cb = wb > 0.0f ? readTarget() : Vec3f(0.0f);
        return (wa * ca + wb * cb) / (wa + wb);
    }
};

template <typename Sampler>
struct Resampler {
    const VolumeSet& source;
    const VolumeSet& target;
    float tauDensity, tauColor;
    Vec3f background;

    /// Fills one output leaf pair with the blended density and colour. Returns false when the
    /// leaf holds nothing.
    bool operator()(const detail::WarpLeaf& w, FloatTree::LeafNodeType& value,
                    Vec3STree::LeafNodeType& color) const
    {
        auto ds = source.density->getConstAccessor();
        auto dt = target.density->getConstAccessor();
        ColorBlend<Sampler> blend(source, target, tauColor, background);
        bool any = false;
        for (openvdb::Index n = 0; n < 512; ++n) {
            const openvdb::Vec3R ps(w.source(n)), pt(w.target(n));
            const float a = sample<Sampler>(ds, ps);
            const float b = sample<Sampler>(dt, pt);
            const float d = (1.0f - tauDensity) * a + tauDensity * b;
            if (!(d > kEmpty)) continue;
            value.setValueOn(n, d);
            any = true;
            color.setValueOn(n, blend(ps, pt, a, b));
        }
        return any;
    }
};

} // namespace

// ------------------------------------------------------------------------------------------------
// Distances beyond the narrow band.

namespace detail {

/// A signed distance field (world units) defined far beyond its narrow band: the band's own values
/// within kNear voxels of the surface, beyond kFar voxels a coarse field (kCoarse voxels apart)
/// extended over a box by OpenVDB's fast sweeping, and a smoothstep between the two.
///
/// The coarse lattice takes the band's exact values where its points fall in the band (every
/// surface has lattice points within sqrt(3) voxels; the band is 3 voxels wide) and the band's sign
/// elsewhere; tools::maskSdf then fills in the distances (to first order: the closed-form test of
/// concentric spheres measures 0.36 voxel at most in the blended band). Its error near the surface
/// is larger, which the transition hides: within kNear voxels the value is the band's. A coarser
/// lattice (4 voxels) was tried: 5 times cheaper to build, but 0.6 voxel off in that test.
class ExtendedDistance {
public:
    static constexpr int kCoarse = 2;
    static constexpr float kNear = 2.0f, kFar = 2.9f; // voxels

    ExtendedDistance(openvdb::FloatGrid::ConstPtr band, const CoordBBox& box)
        : mBand(std::move(band))
    {
        mVoxel = float(mBand->voxelSize()[0]);
        const float background = mBand->background();
        if (box.empty()) return;
        openvdb::FloatGrid::Ptr seeds = openvdb::FloatGrid::create(background);
        seeds->setTransform(
            openvdb::math::Transform::createLinearTransform(kCoarse * double(mVoxel)));
        seeds->setGridClass(openvdb::GRID_LEVEL_SET);
        auto floorDiv = [](int v) {
            return v >= 0 ? v / kCoarse : -((-v + kCoarse - 1) / kCoarse);
        };
        const CoordBBox coarse(
            Coord(floorDiv(box.min().x()), floorDiv(box.min().y()), floorDiv(box.min().z())),
            Coord(floorDiv(box.max().x()) + 1, floorDiv(box.max().y()) + 1,
                  floorDiv(box.max().z()) + 1));
        // Lattice values, in parallel over slabs of x one leaf thick; each slab fills its own tree,
        // and the slabs' leaves are disjoint, so merging moves nodes.
        const int x0 = coarse.min().x() & ~7, slabCount = (coarse.max().x() - x0) / 8 + 1;
        std::vector<openvdb::FloatTree::Ptr> slabs(static_cast<size_t>(slabCount));
        tbb::parallel_for(
            tbb::blocked_range<int>(0, slabCount), [&](const tbb::blocked_range<int>& r) {
                auto fine = mBand->getConstAccessor();
                for (int i = r.begin(); i != r.end(); ++i) {
                    auto tree = std::make_shared<openvdb::FloatTree>(background);
                    openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(*tree);
                    for (int x = std::max(x0 + 8 * i, coarse.min().x());
                         x <= std::min(x0 + 8 * i + 7, coarse.max().x()); ++x)
                        for (int y = coarse.min().y(); y <= coarse.max().y(); ++y)
                            for (int z = coarse.min().z(); z <= coarse.max().z(); ++z) {
                                const Coord fineXyz(x * kCoarse, y * kCoarse, z * kCoarse);
                                float value;
                                if (fine.probeValue(fineXyz, value))
                                    acc.setValueOn(Coord(x, y, z), value);
                                else if (value < 0.0f)
                                    acc.setValueOff(Coord(x, y, z), -background);
                            }
                    slabs[size_t(i)] = tree;
                }
            });
        for (const auto& slab : slabs) seeds->tree().merge(*slab, openvdb::MERGE_NODES);
        openvdb::tools::pruneLevelSet(seeds->tree());
        openvdb::BoolGrid mask(false);
        mask.setTransform(seeds->transform().copy());
        mask.sparseFill(coarse, true, true);
        openvdb::FloatGrid::Ptr wide =
            openvdb::tools::maskSdf(*seeds, mask, /*ignoreActiveTiles*/ false, /*nIter*/ 1);
        if (!wide)
            throw std::runtime_error(
                "Morpher: fast sweeping could not extend a signed distance field");

        // The coarse field, dense over its box for fast reads.
        DenseField& d = mCoarse;
        d.origin = coarse.min();
        d.dim = coarse.dim();
        d.values.resize(size_t(d.dim.x()) * d.dim.y() * d.dim.z());
        tbb::parallel_for(
            tbb::blocked_range<int>(0, d.dim.x()), [&](const tbb::blocked_range<int>& r) {
                auto acc = wide->getConstAccessor();
                for (int x = r.begin(); x != r.end(); ++x)
                    for (int y = 0; y < d.dim.y(); ++y)
                        for (int z = 0; z < d.dim.z(); ++z)
                            d.values[d.index(x, y, z)] = acc.getValue(d.origin.offsetBy(x, y, z));
            });

        // How far the coarse field strays from the band where both are defined (voxels): over
        // the whole band, so that a point whose coarse value is beyond kFar + that needs no fine
        // read; and where the coarse field is used (|band| >= kNear), which bounds how much the
        // extended field can change beyond a distance's 1 per voxel.
        std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
        mBand->tree().getNodes(leaves);
        using Errors = std::pair<float, float>;
        const Errors errors = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, leaves.size()), Errors(0.0f, 0.0f),
            [&](const tbb::blocked_range<size_t>& r, Errors worst) {
                for (size_t i = r.begin(); i != r.end(); ++i)
                    for (auto it = leaves[i]->cbeginValueOn(); it; ++it) {
                        const float e = std::abs(coarseAt(it.getCoord().asVec3d()) - *it);
                        worst.first = std::max(worst.first, e);
                        if (std::abs(*it) >= kNear * mVoxel)
                            worst.second = std::max(worst.second, e);
                    }
                return worst;
            },
            [](Errors a, Errors b) {
                return Errors(std::max(a.first, b.first), std::max(a.second, b.second));
            });
        mCoarseError = errors.first / mVoxel;
        mTransitionError = errors.second / mVoxel;
    }

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
        std::vector<float> values; ///< x-major
        Coord origin, dim;         ///< the box, coarse index space

        size_t index(int x, int y, int z) const { return (size_t(x) * dim.y() + y) * dim.z() + z; }
    };

    openvdb::FloatGrid::ConstPtr mBand;
    DenseField mCoarse;            ///< the extended coarse field over its box
    float mCoarseError = 0.0f;     ///< max |coarse - band| over the band's voxels, voxels
    float mTransitionError = 0.0f; ///< the same where |band| >= kNear
    float mVoxel = 1.0f;
};

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
    IdentityDistances(const CoordBBox& box, size_t maxLeaves)
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
    const Leaf& get(const Coord& origin, ExtendedDistance::Reader<Sampler>& a,
                    ExtendedDistance::Reader<Sampler>& b, Leaf& scratch, uint64_t& computed)
    {
        const Coord leaf = origin >> 3;
        std::atomic<Leaf*>* slot = nullptr;
        if (mSlotCount && mLeaves.isInside(leaf)) {
            const Coord d = leaf - mLeaves.min(), n = mLeaves.dim();
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
        CoordBBox box;
        std::vector<float> source, target;
    };
    template <typename Sampler>
    std::shared_ptr<const Centres> centres(const CoordBBox& box, const ExtendedDistance& farSource,
                                           const ExtendedDistance& farTarget)
    {
        {
            std::lock_guard<std::mutex> lock(mCentresMutex);
            if (mCentres && mCentres->box == box) return mCentres;
        }
        auto c = std::make_shared<Centres>();
        c->box = box;
        const CoordBBox leaves = box >> size_t(3);
        const Coord n = leaves.dim();
        c->source.resize(size_t(n.x()) * n.y() * n.z());
        c->target.resize(c->source.size());
        tbb::parallel_for(tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
            ExtendedDistance::Reader<Sampler> a(farSource), b(farTarget);
            for (int x = r.begin(); x != r.end(); ++x)
                for (int y = 0; y < n.y(); ++y)
                    for (int z = 0; z < n.z(); ++z) {
                        const Coord leaf = leaves.min().offsetBy(x, y, z);
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
    CoordBBox mLeaves; ///< leaf coordinates (index >> 3)
    std::mutex mCentresMutex;
    std::shared_ptr<const Centres> mCentres;
    size_t mMax;
    size_t mSlotCount = 0;
    std::unique_ptr<std::atomic<Leaf*>[]> mSlots;
    std::atomic<size_t> mCount{0};
};

} // namespace detail

namespace {

/// The 8^3 blocks (leaves) of a frame's box that can hold the blended band, found from the blend
/// at their centres. |grad blend| <= G (the warp's stretch; the distances are 1-Lipschitz), so a
/// block whose centre value is beyond G (r + width) + slack holds no value within `width` of zero
/// and takes its centre's sign throughout (r: the distance from the centre to a corner voxel).
struct BlockClasses {
    CoordBBox leaves;           ///< in leaf coordinates (index >> 3)
    std::vector<int8_t> kind;   ///< per leaf: 0 evaluate, +1 outside, -1 inside
    std::vector<float> stretch; ///< per leaf: G there
    std::vector<float> band; ///< per leaf: the compute band there (world units; SdfFrame::classify)
    double maxStretch = 1.0; ///< G over the box

    size_t index(const Coord& leaf) const
    {
        const Coord d = leaf - leaves.min(), n = leaves.dim();
        return (size_t(d.x()) * n.y() + d.y()) * n.z() + d.z();
    }

    int8_t at(const Coord& leaf) const { return kind[index(leaf)]; }
    /// Does `cells` (index space) overlap a leaf to evaluate?
    bool anyToEvaluate(const CoordBBox& cells) const
    {
        CoordBBox b = cells >> size_t(3); // leaf coordinates
        b.intersect(leaves);
        for (int x = b.min().x(); x <= b.max().x(); ++x)
            for (int y = b.min().y(); y <= b.max().y(); ++y)
                for (int z = b.min().z(); z <= b.max().z(); ++z)
                    if (at(Coord(x, y, z)) == 0) return true;
        return false;
    }
};

/// The largest of `values` over each leaf's 3^3 neighbourhood within the box (`dim` leaves on a
/// side, indexed as BlockClasses::index does).
std::vector<float> neighbourhoodMax(const std::vector<float>& values, const Coord& dim)
{
    auto index = [&dim](int x, int y, int z) { return (size_t(x) * dim.y() + y) * dim.z() + z; };
    std::vector<float> out(values.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, dim.x()), [&](const tbb::blocked_range<int>& r) {
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < dim.y(); ++y)
                for (int z = 0; z < dim.z(); ++z) {
                    float m = -std::numeric_limits<float>::max();
                    for (int i = std::max(0, x - 1); i <= std::min(dim.x() - 1, x + 1); ++i)
                        for (int j = std::max(0, y - 1); j <= std::min(dim.y() - 1, y + 1); ++j)
                            for (int k = std::max(0, z - 1); k <= std::min(dim.z() - 1, z + 1); ++k)
                                m = std::max(m, values[index(i, j, k)]);
                    out[index(x, y, z)] = m;
                }
    });
    return out;
}

/// One sdf-mode frame: the blend of the two extended distances through their warps, evaluated
/// only in the blocks that can hold its narrow band, redistanced there, with colour on the band.
template <typename Sampler>
class SdfFrame {
public:
    SdfFrame(const VolumeSet& source, const VolumeSet& target,
             const detail::ExtendedDistance& farSource, const detail::ExtendedDistance& farTarget,
             const InverseWarp& warp, float tauSdf, float tauColor, Vec3f background,
             double toleranceVoxels)
        : mSource(source), mTarget(target), mFarSource(farSource), mFarTarget(farTarget),
          mWarp(warp), mTau(tauSdf), mTauColor(tauColor), mBackground(background),
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
    void classify(const CoordBBox& box, bool prune, detail::IdentityDistances* identity = nullptr)
    {
        BlockClasses& c = mClasses;
        c.leaves = box >> size_t(3);
        const Coord n = c.leaves.dim();
        const size_t count = size_t(n.x()) * n.y() * n.z();
        auto index = [&n](int x, int y, int z) { return (size_t(x) * n.y() + y) * n.z() + z; };
        std::vector<float> blend(count);
        std::vector<Vec3d> ps, pt;
        if (identity) {
            const auto centres = identity->centres<Sampler>(box, mFarSource, mFarTarget);
            for (size_t i = 0; i < count; ++i)
                blend[i] = (1.0f - mTau) * centres->source[i] + mTau * centres->target[i];
        } else {
            ps.resize(count);
            pt.resize(count);
            tbb::parallel_for(
                tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
                    typename detail::ExtendedDistance::template Reader<Sampler> a(mFarSource),
                        b(mFarTarget);
                    for (int x = r.begin(); x != r.end(); ++x)
                        for (int y = 0; y < n.y(); ++y)
                            for (int z = 0; z < n.z(); ++z) {
                                const size_t i = index(x, y, z);
                                const Coord leaf = c.leaves.min().offsetBy(x, y, z);
                                const Vec3d centre(leaf.x() * 8 + 3.5, leaf.y() * 8 + 3.5,
                                                   leaf.z() * 8 + 3.5);
                                mWarp.map(centre, ps[i], pt[i]);
                                blend[i] = (1.0f - mTau) * a(ps[i]) + mTau * b(pt[i]);
                            }
                });
        }
        // The warp's stretch per leaf: the spectral norm of its Jacobian by differences between
        // neighbouring centres, the largest over the 3^3 neighbourhood, with a margin of 1.25 for
        // what varies between centres. The identity's is 1 exactly.
        std::vector<float> stretch(count, 1.0f);
        if (mWarp.pairCount() > 0) {
            std::vector<float> own(count, 1.0f);
            auto norm = [](const Vec3d& dx, const Vec3d& dy, const Vec3d& dz) {
                return detail::spectralNorm(dx, dy, dz) / 8.0;
            };
            auto diff = [&](const std::vector<Vec3d>& p, int x, int y, int z, int axis) {
                Coord a(x, y, z), b(x, y, z);
                if (b[axis] + 1 < n[axis])
                    b[axis] += 1;
                else if (a[axis] > 0)
                    a[axis] -= 1;
                else
                    return Vec3d(0.0);
                return p[index(b.x(), b.y(), b.z())] - p[index(a.x(), a.y(), a.z())];
            };
            tbb::parallel_for(
                tbb::blocked_range<int>(0, n.x()), [&](const tbb::blocked_range<int>& r) {
                    for (int x = r.begin(); x != r.end(); ++x)
                        for (int y = 0; y < n.y(); ++y)
                            for (int z = 0; z < n.z(); ++z) {
                                const double s = norm(diff(ps, x, y, z, 0), diff(ps, x, y, z, 1),
                                                      diff(ps, x, y, z, 2));
                                const double t = norm(diff(pt, x, y, z, 0), diff(pt, x, y, z, 1),
                                                      diff(pt, x, y, z, 2));
                                own[index(x, y, z)] = float((1.0 - mTau) * s + mTau * t);
                            }
                });
            stretch = neighbourhoodMax(own, n);
            for (float& g : stretch) g = std::max(1.0f, 1.25f * g);
        }
        c.maxStretch = *std::max_element(stretch.begin(), stretch.end());
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
    float width() const { return mWidth * mVoxel; }
    uint64_t samples() const { return mSamples + mClasses.kind.size(); }
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

    /// The leaf's bands (world units): its compute band, and the band that is kept.
    struct Bands {
        float compute, keep;
    };
    Bands bandsAt(const Coord& origin) const
    {
        const size_t i = mClasses.index(origin >> size_t(3));
        return {mClasses.band[i], mClasses.stretch[i] * mWidth * mVoxel};
    }

    /// Blends voxel n from its two distances: active within the compute band, +/- the band
    /// (inactive) beyond it; its colour, colorAt(), within the band that is kept.
    template <typename ColorAt>
    void blendVoxel(openvdb::Index n, float da, float db, const Bands& bands,
                    FloatTree::LeafNodeType& value, Vec3STree::LeafNodeType& color, Seen& seen,
                    const ColorAt& colorAt) const
    {
        const float d = (1.0f - mTau) * da + mTau * db;
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
    int operator()(const detail::WarpLeaf& w, FloatTree::LeafNodeType& value,
                   Vec3STree::LeafNodeType& color) const
    {
        typename detail::ExtendedDistance::template Reader<Sampler> a(mFarSource), b(mFarTarget);
        ColorBlend<Sampler> colors(mSource, mTarget, mTauColor, mBackground);
        // Each side's colour weight is its fog at the warped point, derived from its distance
        // with the output's ramp: what "empty there" means for a surface.
        const float ramp = kSdfRampVoxels * mVoxel;
        Seen seen;
        uint64_t samples = 0;
        // Each 4^3 quarter of the leaf is first judged by its voxel (2, 2, 2), at most 2 sqrt(3)
        // voxels from the others, then each of its 2^3 blocks by the blend at the mean of its
        // voxels' warped points: voxel v is within sum_u |p(v) - p(u)| / 8 <= G (3 + 3 sqrt(2) +
        // sqrt(3)) / 8 of that mean. Beyond the limit a quarter or block is inside or outside as a
        // whole.
        const float stretch = mClasses.stretch[mClasses.index(w.origin >> size_t(3))];
        const Bands bands = bandsAt(w.origin);
        const float quarterLimit = limit(stretch, 2.0f * kSqrt3, bands.compute);
        const float blockLimit = limit(stretch, kBlockReach, bands.compute);
        auto fill = [&](int x0, int y0, int z0, int size, float d) {
            const float v = d < 0.0f ? -bands.compute : bands.compute;
            for (int i = x0; i < x0 + size; ++i)
                for (int j = y0; j < y0 + size; ++j)
                    for (int k = z0; k < z0 + size; ++k)
                        value.setValueOff(openvdb::Index((i * 8 + j) * 8 + k), v);
            (d < 0.0f ? seen.inside : seen.outside) = true;
        };
        for (int q = 0; q < 8; ++q) {
            const int qx = (q & 1) * 4, qy = ((q >> 1) & 1) * 4, qz = ((q >> 2) & 1) * 4;
            if (mPrune) {
                const openvdb::Index c = ((qx + 2) * 8 + qy + 2) * 8 + qz + 2;
                const float d = (1.0f - mTau) * a(openvdb::Vec3R(w.source(c))) +
                                mTau * b(openvdb::Vec3R(w.target(c)));
                ++samples;
                if (!(std::abs(d) < quarterLimit)) {
                    fill(qx, qy, qz, 4, d);
                    continue;
                }
            }
            for (int bq = 0; bq < 8; ++bq) {
                const int bx = qx + (bq & 1) * 2, by = qy + ((bq >> 1) & 1) * 2,
                          bz = qz + ((bq >> 2) & 1) * 2;
                if (mPrune) {
                    Vec3f ms(0.0f), mt(0.0f);
                    for (int v = 0; v < 8; ++v) {
                        const openvdb::Index n = openvdb::Index(
                            ((bx + (v & 1)) * 8 + by + ((v >> 1) & 1)) * 8 + bz + (v >> 2));
                        ms += w.source(n);
                        mt += w.target(n);
                    }
                    const float d = (1.0f - mTau) * a(openvdb::Vec3R(ms * 0.125f)) +
                                    mTau * b(openvdb::Vec3R(mt * 0.125f));
                    ++samples;
                    if (!(std::abs(d) < blockLimit)) {
                        fill(bx, by, bz, 2, d);
                        continue;
                    }
                }
                for (int i = bx; i < bx + 2; ++i)
                    for (int j = by; j < by + 2; ++j)
                        for (int k = bz; k < bz + 2; ++k) {
                            const openvdb::Index n = openvdb::Index((i * 8 + j) * 8 + k);
                            const openvdb::Vec3R ps(w.source(n)), pt(w.target(n));
                            const float da = a(ps), db = b(pt);
                            ++samples;
                            blendVoxel(n, da, db, bands, value, color, seen, [&] {
                                return colors(ps, pt, fogRamp(da, ramp), fogRamp(db, ramp));
                            });
                        }
            }
        }
        mSamples += samples;
        return seen.whole();
    }

    /// Fills one leaf as operator() does, from the two distances at its voxels (the identity
    /// warp's points, cached across frames). Every voxel is blended: from distances at hand that is
    /// cheaper than judging quarters and blocks, and gives the same leaf (what those judgements
    /// skip is beyond the compute band, with their sign).
    int operator()(const Coord& origin, const detail::IdentityDistances::Leaf& distances,
                   FloatTree::LeafNodeType& value, Vec3STree::LeafNodeType& color) const
    {
        ColorBlend<Sampler> colors(mSource, mTarget, mTauColor, mBackground);
        const float ramp = kSdfRampVoxels * mVoxel;
        Seen seen;
        const Bands bands = bandsAt(origin);
        for (openvdb::Index n = 0; n < 512; ++n) {
            const float da = distances.source[n], db = distances.target[n];
            blendVoxel(n, da, db, bands, value, color, seen, [&] {
                return colors.atVoxel(origin + value.offsetToLocalCoord(n), fogRamp(da, ramp),
                                      fogRamp(db, ramp));
            });
        }
        return seen.whole();
    }

    void addSamples(uint64_t n) const { mSamples += n; }

    /// Rebuilds the band from the blend in place and returns the fog derived from it, in one pass
    /// over the leaves. Each band voxel gets its distance to the blend's zero set to first order,
    /// |b| / |grad b| by central differences, and never more than the distance to a zero crossing
    /// on one of its six edges (found by linear interpolation, as OpenVDB's fast sweeping seeds
    /// its front). The band is then cut to the output width (voxels at or beyond it inactive,
    /// +/- the width), and the fog is fogFromLevelSet's of the result: fogRamp(d, ramp) on the
    /// band, 1 (active) inside, 0 outside.
    openvdb::FloatGrid::Ptr redistance(openvdb::FloatGrid& values, float ramp) const
    {
        using Leaf = FloatTree::LeafNodeType;
        openvdb::tree::LeafManager<FloatTree> leaves(values.tree(), 1);
        const float width = mWidth * mVoxel;
        std::vector<Leaf::NodeMaskType> bands(leaves.leafCount());
        std::vector<std::unique_ptr<Leaf>> fogs(leaves.leafCount());
        // Central differences as math::GradStencil takes them. The six neighbours are read from
        // the leaf's buffer, or from the buffer of the neighbouring leaf across that face, or,
        // where there is none (a tile), through an accessor. Only the aux buffers are written
        // here, so every read sees the blend.
        const float inv2dx = float(0.5 / values.voxelSize()[0]);
        leaves.foreach ([&](Leaf& leaf, size_t index) {
            auto acc = values.getConstAccessor();
            const Coord origin = leaf.origin();
            // Per face (+x, -x, +y, -y, +z, -z): the neighbouring leaf's values, and the step of
            // the voxel index inside a leaf and across the face.
            const float* across[6];
            constexpr int kStep[6] = {64, -64, 8, -8, 1, -1},
                          kWrap[6] = {-448, 448, -56, 56, -7, 7};
            for (int f = 0; f < 6; ++f) {
                const int axis = f / 2, sign = f % 2 ? -1 : 1;
                Coord o = origin;
                o[axis] += 8 * sign;
                const Leaf* next = acc.probeConstLeaf(o);
                across[f] = next ? next->buffer().data() : nullptr;
            }
            // Only voxels within the leaf's kept band can come within the width of the zero set.
            const float keep = mClasses.leaves.isInside(origin >> size_t(3))
                                   ? bandsAt(origin).keep
                                   : float(mClasses.maxStretch) * width;
            const float* in = leaf.buffer().data();
            float* out = leaves.getBuffer(index, 1).data();
            auto fog = std::make_unique<Leaf>(origin, 0.0f, false);
            Leaf::NodeMaskType& band = bands[index];
            for (openvdb::Index n = 0; n < Leaf::SIZE; ++n) {
                const float b = in[n];
                float dist = width;
                if (leaf.isValueOn(n) && std::abs(b) < keep) {
                    const int ijk[3] = {int(n >> 6), int((n >> 3) & 7), int(n & 7)};
                    float e[6]; // +x, -x, +y, -y, +z, -z
                    for (int f = 0; f < 6; ++f) {
                        const int c = ijk[f / 2];
                        if (f % 2 ? c > 0 : c < 7)
                            e[f] = in[int(n) + kStep[f]];
                        else if (across[f])
                            e[f] = across[f][int(n) + kWrap[f]];
                        else {
                            Coord q = origin.offsetBy(ijk[0], ijk[1], ijk[2]);
                            q[f / 2] += f % 2 ? -1 : 1;
                            e[f] = acc.getValue(q);
                        }
                    }
                    const Vec3f gradient = Vec3f(e[0] - e[1], e[2] - e[3], e[4] - e[5]) * inv2dx;
                    const float g = gradient.length(); // world-space, 1 for a distance
                    if (g > 1e-6f) dist = std::abs(b) / g;
                    for (float v : e)
                        if ((v < 0.0f) != (b < 0.0f))
                            dist =
                                std::min(dist, mVoxel * std::abs(b) / (std::abs(b) + std::abs(v)));
                    dist = std::min(dist, width);
                }
                const float d = b < 0.0f ? -dist : dist;
                const bool on = dist < width;
                out[n] = d;
                band.set(n, on);
                const float density = fogOfLevelSet(d, on, ramp);
                if (density > 0.0f) fog->setValueOn(n, density);
            }
            fogs[index] = std::move(fog);
        });
        leaves.swapLeafBuffer(1);
        leaves.foreach ([&bands](Leaf& leaf, size_t index) { leaf.setValueMask(bands[index]); });
        // Every leaf value is now in the band or +/- the width. Inactive tiles hold +/- the width
        // already (the grid was made so); active ones, if any, are deep inside or outside and
        // become so too. The tiles inside are the fog's interior tiles: they are looked for in
        // each internal node's own tile table, which is much cheaper than the tree's iterator.
        openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
        FloatTree& fog = density->tree();
        for (auto& leaf : fogs) fog.addLeaf(leaf.release());
        FloatTree& tree = values.tree();
        if (!openvdb::math::isExactlyEqual(tree.background(), width))
            throw std::logic_error(
                "SdfFrame::redistance: the grid's background must be the band's width");
        auto active = tree.beginValueOn();
        active.setMaxDepth(active.getLeafDepth() - 1);
        for (; active; ++active) {
            active.setValue(*active < 0.0f ? -width : width);
            active.setValueOff();
        }
        auto insideTiles = [&fog](const auto& nodes) {
            for (const auto* node : nodes)
                for (auto it = node->cbeginValueAll(); it; ++it) // tiles, not children
                    if (*it < 0.0f) fog.addTile(node->LEVEL, it.getCoord(), 1.0f, true);
        };
        std::vector<const FloatTree::RootNodeType::ChildNodeType*> upper;
        std::vector<const FloatTree::RootNodeType::ChildNodeType::ChildNodeType*> lower;
        tree.getNodes(upper);
        tree.getNodes(lower);
        insideTiles(upper);
        insideTiles(lower);
        for (auto it = tree.root().cbeginValueAll(); it; ++it)
            if (*it < 0.0f) fog.addTile(FloatTree::RootNodeType::LEVEL, it.getCoord(), 1.0f, true);
        openvdb::tools::prune(fog);
        openvdb::tools::pruneLevelSet(tree);
        return density;
    }

private:
    const VolumeSet& mSource;
    const VolumeSet& mTarget;
    const detail::ExtendedDistance& mFarSource;
    const detail::ExtendedDistance& mFarTarget;
    const InverseWarp& mWarp;
    float mTau, mTauColor;
    Vec3f mBackground;
    float mVoxel;              ///< world units
    float mWidth;              ///< the output band's half width, voxels
    float mSlack;              ///< voxels
    float mComputeBand = 0.0f; ///< the widest compute band (world units)
    bool mPrune = true;
    BlockClasses mClasses;
    mutable std::atomic<uint64_t> mSamples{0};
};

} // namespace

Morpher::Morpher(VolumeSet source, VolumeSet target, std::vector<FeaturePairSpec> pairs,
                 WarpSpec warp, BlendSpec blend, MorphOptions options)
    : mSource(std::move(source)), mTarget(std::move(target)), mPairs(std::move(pairs)), mWarp(warp),
      mBlend(std::move(blend)), mOptions(options)
{
    if (!mSource.density || !mTarget.density || !mSource.color || !mTarget.color)
        throw std::invalid_argument("Morpher: source and target need density and Cd grids");
    if (mBlend.mode == BlendMode::Sdf && (!mSource.sdf || !mTarget.sdf))
        throw std::invalid_argument("Morpher: sdf blending needs sdf grids on both sides");
    if (!(mSource.density->transform() == mTarget.density->transform()))
        throw std::invalid_argument("Morpher: source and target must share one transform");
    mSourceBlocks = std::make_shared<const detail::Occupancy>(mSource.density->tree());
    mTargetBlocks = std::make_shared<const detail::Occupancy>(mTarget.density->tree());
    if (mBlend.mode == BlendMode::Sdf) {
        CoordBBox box = mSource.sdf->evalActiveVoxelBoundingBox();
        box.expand(mTarget.sdf->evalActiveVoxelBoundingBox());
        if (!box.empty()) {
            // A margin for warped points that leave the box: an eighth of its size, at least 8
            // voxels. With no pairs the points are the output's voxels: the blend's zero set lies
            // within the objects' box (the band's active voxels), and 8 voxels more hold its
            // compute band. Beyond the box a read takes the nearest face's value, which
            // underestimates a distance outside: leaves there are judged, if anything, too near
            // (4 voxels: 15% more leaves evaluated, for a setup hardly cheaper).
            const Coord dim = box.dim();
            const int margin =
                mPairs.empty() ? 8 : std::max(8, std::max({dim.x(), dim.y(), dim.z()}) / 8);
            box.expand(margin);
        }
        // Both at once: fast sweeping is partly serial.
        tbb::parallel_invoke(
            [&] {
                mFarSource = std::make_shared<const detail::ExtendedDistance>(mSource.sdf, box);
            },
            [&] {
                mFarTarget = std::make_shared<const detail::ExtendedDistance>(mTarget.sdf, box);
            });
        if (mPairs.empty()) {
            const uint64_t limit =
                mOptions.memoryLimitBytes ? mOptions.memoryLimitBytes : defaultMemoryLimitBytes();
            mIdentity = std::make_shared<detail::IdentityDistances>(
                candidateBounds(0.0), size_t(limit / 4 / sizeof(detail::IdentityDistances::Leaf)));
        }
    }
}

CoordBBox Morpher::candidateBounds(double t) const
{
    // The occupied blocks' bounds and a block more on each side.
    CoordBBox s = mSourceBlocks->bounds(), d = mTargetBlocks->bounds();
    if (!s.empty()) s.expand(8);
    if (!d.empty()) d.expand(8);
    CoordBBox box;
    if (!s.empty()) box.expand(s);
    if (!d.empty()) box.expand(d);
    const InverseWarp warp(mPairs, mWarp, t, 1.0 / mSource.voxelSize());
    for (size_t i = 0; i < warp.pairCount(); ++i) {
        if (!s.empty()) box.expand(inverseImage(warp.sourceAffine(i), s));
        if (!d.empty()) box.expand(inverseImage(warp.targetAffine(i), d));
    }
    if (box.empty()) return box;
    // The blend of several affine maps can reach a little past each one's image.
    const Coord dim = box.dim();
    const Coord margin(16 + dim.x() / 8, 16 + dim.y() / 8, 16 + dim.z() / 8);
    return CoordBBox(box.min() - margin, box.max() + margin);
}

VolumeSet Morpher::frame(double t, MorphStats* stats, Interrupter* interrupter) const
{
    return run(t, candidateBounds(t), true, mWarp.toleranceVoxels, stats, interrupter);
}

VolumeSet Morpher::frameOverBox(double t, const CoordBBox& box, double tolerance,
                                MorphStats* stats) const
{
    return run(t, box, false, tolerance, stats, nullptr);
}

namespace {

/// The output leaves of one frame, collected from the warp's threads, under the memory guard: a
/// warp that blows the shape up (a pair scaling by 100, say) would otherwise fill the machine's
/// memory leaf by leaf.
class LeafCollector {
public:
    LeafCollector(double t, uint64_t limitBytes, Vec3f background)
        : mT(t), mLimit(limitBytes ? limitBytes : defaultMemoryLimitBytes()),
          mMaxLeaves(size_t(std::max<uint64_t>(1, mLimit / kMorphBytesPerLeaf))),
          mBackground(background)
    {
    }
    ~LeafCollector()
    {
        for (auto& [value, color] : mLeaves) {
            delete value;
            delete color;
        }
    }
    LeafCollector(const LeafCollector&) = delete;
    LeafCollector& operator=(const LeafCollector&) = delete;

    /// A value leaf (background `value`, inactive) and a colour leaf at `origin`.
    std::pair<std::unique_ptr<FloatTree::LeafNodeType>, std::unique_ptr<Vec3STree::LeafNodeType>>
    make(const Coord& origin, float value) const
    {
        return {std::make_unique<FloatTree::LeafNodeType>(origin, value, false),
                std::make_unique<Vec3STree::LeafNodeType>(origin, mBackground, false)};
    }

    void keep(std::unique_ptr<FloatTree::LeafNodeType> value,
              std::unique_ptr<Vec3STree::LeafNodeType> color)
    {
        std::lock_guard<std::mutex> lock(mMutex);
        if (mLeaves.size() >= mMaxLeaves) {
            char text[300];
            std::snprintf(
                text, sizeof text,
                "the in-between at t = %.4f needs more than the memory limit of %.1f GiB (over %zu "
                "blocks of 8^3 voxels); use a larger voxel size, check the feature pairs' scales, "
                "or "
                "raise --memory-limit (default: half the machine's memory)",
                mT, double(mLimit) / double(1ull << 30), mMaxLeaves);
            throw UserError(SourceLocation{"morph"}, text);
        }
        mLeaves.emplace_back(value.release(), color.release());
    }

    void insideTile(const Coord& origin)
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mInside.push_back(origin);
    }

    size_t size() const { return mLeaves.size(); }

    /// Moves the leaves into the two trees; inside tiles (leaf-sized) get `insideValue`.
    void moveInto(FloatTree& values, Vec3STree& colors, float insideValue)
    {
        for (auto& [value, color] : mLeaves) {
            values.addLeaf(value);
            colors.addLeaf(color);
        }
        mLeaves.clear();
        for (const Coord& origin : mInside) values.addTile(1, origin, insideValue, false);
    }

private:
    double mT;
    uint64_t mLimit;
    size_t mMaxLeaves;
    Vec3f mBackground;
    std::mutex mMutex;
    std::vector<std::pair<FloatTree::LeafNodeType*, Vec3STree::LeafNodeType*>> mLeaves;
    std::vector<Coord> mInside;
};

/// The grids' names, classes and transform, and the stats, common to both modes.
void finish(VolumeSet& out, const openvdb::math::Transform& xform, MorphStats* stats,
            const detail::AdaptiveWarpStats& warpStats, size_t outputLeaves)
{
    openvdb::tools::prune(out.color->tree());
    out.color->setTransform(xform.copy());
    out.density->setTransform(xform.copy());
    out.density->setName(kDensityGridName);
    out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    out.color->setName(kColorGridName);
    out.color->setVectorType(openvdb::VEC_INVARIANT);
    if (stats) {
        stats->maxWarpErrorVoxels = warpStats.maxErrorVoxels;
        stats->exactEvaluations = warpStats.exactEvaluations;
        stats->candidateLeaves = warpStats.leaves;
        stats->outputLeaves = outputLeaves;
        stats->activeVoxels = out.density->activeVoxelCount();
    }
}

} // namespace

VolumeSet Morpher::run(double t, const CoordBBox& box, bool prune, double tolerance,
                       MorphStats* stats, Interrupter* interrupter) const
{
    if (mBlend.mode == BlendMode::Sdf) return runSdf(t, box, prune, tolerance, stats, interrupter);
    const double voxel = mSource.voxelSize();
    const InverseWarp warp(mPairs, mWarp, t, 1.0 / voxel);
    const detail::AdaptiveWarp adaptive(warp, tolerance);
    const detail::Occupancy* occS = prune ? mSourceBlocks.get() : nullptr;
    const detail::Occupancy* occT = prune ? mTargetBlocks.get() : nullptr;
    const float tauD = float(mBlend.density.evaluate(t)), tauC = float(mBlend.color.evaluate(t));
    const Vec3f background =
        (1.0f - tauC) * mSource.color->background() + tauC * mTarget.color->background();

    LeafCollector leaves(t, mOptions.memoryLimitBytes, background);
    auto each = [&](auto resampler) {
        return [&, resampler](const detail::WarpLeaf& w) {
            auto [density, color] = leaves.make(w.origin, 0.0f);
            if (resampler(w, *density, *color)) leaves.keep(std::move(density), std::move(color));
        };
    };
    detail::AdaptiveWarpStats warpStats;
    if (mOptions.sampling == MorphOptions::Sampling::Triquadratic)
        adaptive.forEachLeaf(box, occS, occT,
                             each(Resampler<openvdb::tools::QuadraticSampler>{
                                 mSource, mTarget, tauD, tauC, background}),
                             &warpStats, interrupter);
    else
        adaptive.forEachLeaf(
            box, occS, occT,
            each(Resampler<openvdb::tools::BoxSampler>{mSource, mTarget, tauD, tauC, background}),
            &warpStats, interrupter);

    VolumeSet out;
    out.density = openvdb::FloatGrid::create(0.0f);
    out.color = openvdb::Vec3SGrid::create(background);
    const size_t kept = leaves.size();
    leaves.moveInto(out.density->tree(), out.color->tree(), 0.0f);
    openvdb::tools::prune(out.density->tree()); // leaves of constant interior collapse into tiles
    finish(out, mSource.density->transform(), stats, warpStats, kept);
    return out;
}

VolumeSet Morpher::runSdf(double t, const CoordBBox& box, bool prune, double tolerance,
                          MorphStats* stats, Interrupter* interrupter) const
{
    if (mOptions.sampling == MorphOptions::Sampling::Triquadratic)
        return runSdf<openvdb::tools::QuadraticSampler>(t, box, prune, tolerance, stats,
                                                        interrupter);
    return runSdf<openvdb::tools::BoxSampler>(t, box, prune, tolerance, stats, interrupter);
}

template <typename Sampler>
VolumeSet Morpher::runSdf(double t, const CoordBBox& box, bool prune, double tolerance,
                          MorphStats* stats, Interrupter* interrupter) const
{
    // The blend of two warped, extended distances has the right zero set but is no distance
    // field. It is evaluated only in the leaves that can hold its band (SdfFrame::classify; the
    // others are inside or outside as a whole), cleared of dust, redistanced to first order on
    // the band, and the fog is derived from the result.
    const double voxel = mSource.voxelSize();
    const InverseWarp warp(mPairs, mWarp, t, 1.0 / voxel);
    const detail::AdaptiveWarp adaptive(warp, tolerance);
    const float tauC = float(mBlend.color.evaluate(t)), tauS = float(mBlend.sdf.evaluate(t));
    const Vec3f background =
        (1.0f - tauC) * mSource.color->background() + tauC * mTarget.color->background();

    SdfFrame<Sampler> blend(mSource, mTarget, *mFarSource, *mFarTarget, warp, tauS, tauC,
                            background, tolerance);
    // With no pairs (and pruning), distances are read from those kept across frames.
    detail::IdentityDistances* const keptDistances =
        prune && warp.pairCount() == 0 ? mIdentity.get() : nullptr;
    blend.classify(box, prune, keptDistances);
    const float band = blend.computeBand();
    LeafCollector leaves(t, mOptions.memoryLimitBytes, background);
    const BlockClasses& classes = blend.classes();
    std::vector<Coord> evaluate; // with kept distances, the leaves to evaluate
    for (int x = classes.leaves.min().x(); x <= classes.leaves.max().x(); ++x)
        for (int y = classes.leaves.min().y(); y <= classes.leaves.max().y(); ++y)
            for (int z = classes.leaves.min().z(); z <= classes.leaves.max().z(); ++z) {
                const int8_t kind = classes.at(Coord(x, y, z));
                if (kind < 0)
                    leaves.insideTile(Coord(x * 8, y * 8, z * 8));
                else if (kind == 0 && keptDistances)
                    evaluate.emplace_back(x * 8, y * 8, z * 8);
            }
    const detail::AdaptiveWarp::CellFilter wanted = [&classes](const CoordBBox& cells) {
        return classes.anyToEvaluate(cells);
    };
    detail::AdaptiveWarpStats warpStats;
    if (keptDistances) {
        std::atomic<bool> stopped{false};
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, evaluate.size(), 8),
            [&](const tbb::blocked_range<size_t>& r) {
                if (stopped || (interrupter && interrupter->wasInterrupted(
                                                   int(100 * r.begin() / evaluate.size())))) {
                    stopped = true;
                    return;
                }
                typename detail::ExtendedDistance::template Reader<Sampler> a(*mFarSource),
                    b(*mFarTarget);
                auto scratch = std::make_unique<detail::IdentityDistances::Leaf>();
                uint64_t computed = 0;
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    const auto& distances =
                        keptDistances->get<Sampler>(evaluate[i], a, b, *scratch, computed);
                    auto [value, color] = leaves.make(evaluate[i], band);
                    const int whole = blend(evaluate[i], distances, *value, *color);
                    if (whole == 0)
                        leaves.keep(std::move(value), std::move(color));
                    else if (whole < 0)
                        leaves.insideTile(evaluate[i]);
                }
                blend.addSamples(computed);
            });
        if (stopped) throw Interrupted();
        warpStats.leaves = evaluate.size();
    } else {
        adaptive.forEachLeaf(
            box, nullptr, nullptr,
            [&](const detail::WarpLeaf& w) {
                auto [value, color] = leaves.make(w.origin, band);
                const int whole = blend(w, *value, *color);
                if (whole == 0)
                    leaves.keep(std::move(value), std::move(color));
                else if (whole < 0)
                    leaves.insideTile(w.origin);
            },
            &warpStats, interrupter, prune ? &wanted : nullptr);
    }

    // Tiles and the background take the output band's values at once (+/- its width); the
    // leaves' values beyond the compute band are rewritten by redistance().
    openvdb::FloatGrid::Ptr values = openvdb::FloatGrid::create(blend.width());
    values->setTransform(mSource.density->transform().copy());
    values->setGridClass(openvdb::GRID_LEVEL_SET);
    VolumeSet out;
    out.color = openvdb::Vec3SGrid::create(background);
    const size_t kept = leaves.size();
    leaves.moveInto(values->tree(), out.color->tree(), -blend.width());
    dropIslands(*values, mBlend.minIslandVoxels, band, blend.deepVoxels());
    out.density = blend.redistance(*values, kSdfRampVoxels * float(voxel));
    out.sdf = values;
    out.sdf->setName(kSdfGridName);
    finish(out, mSource.density->transform(), stats, warpStats, kept);
    if (stats) stats->blendSamples = blend.samples();
    return out;
}

} // namespace volmorph
