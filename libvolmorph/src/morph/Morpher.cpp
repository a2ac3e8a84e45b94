// Domain, warp, resample, blend. One of the few translation units with OpenVDB's tools headers.
#include <volmorph/Morph.h>
#include <volmorph/Warp.h>

#include "warp/AdaptiveWarp.h"

#include <volmorph/Diagnostics.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/util/Util.h>

#include <memory>
#include <mutex>
#include <cstdio>

namespace volmorph {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatTree;
using openvdb::Vec3STree;

/// Densities at or below this are empty (a trilinear sample at the edge of a fog's support).
constexpr float kEmpty = 1e-6f;

/// The box of the 8 corners of `box` under p -> M^-1 (p - b), M and b of `a`.
CoordBBox inverseImage(const InverseWarp::Affine& a, const CoordBBox& box)
{
    const openvdb::math::Mat3d m(a.col[0], a.col[1], a.col[2], /*rows=*/false);
    const openvdb::math::Mat3d inv = m.inverse();
    Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (int k = 0; k < 8; ++k) {
        const Vec3d p((k & 1) ? box.max().x() : box.min().x(), (k & 2) ? box.max().y() : box.min().y(),
                      (k & 4) ? box.max().z() : box.min().z());
        const Vec3d d = p - a.offset;
        const Vec3d q(inv(0, 0) * d.x() + inv(0, 1) * d.y() + inv(0, 2) * d.z(),
                      inv(1, 0) * d.x() + inv(1, 1) * d.y() + inv(1, 2) * d.z(),
                      inv(2, 0) * d.x() + inv(2, 1) * d.y() + inv(2, 2) * d.z());
        lo = minComponent(lo, q);
        hi = maxComponent(hi, q);
    }
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e8, 1.0e8)); };
    return CoordBBox(Coord(clampInt(std::floor(lo.x())), clampInt(std::floor(lo.y())), clampInt(std::floor(lo.z()))),
                     Coord(clampInt(std::ceil(hi.x())), clampInt(std::ceil(hi.y())), clampInt(std::ceil(hi.z()))));
}

/// `sdf` with its distances extended by fast sweeping over `box` (index space); elsewhere it keeps
/// its narrow band.
openvdb::FloatGrid::Ptr extendedDistances(const openvdb::FloatGrid& sdf, const CoordBBox& box)
{
    openvdb::BoolGrid mask(false);
    mask.setTransform(sdf.transform().copy());
    mask.sparseFill(box, true, true);
    openvdb::FloatGrid::Ptr wide = openvdb::tools::maskSdf(sdf, mask, /*ignoreActiveTiles*/ false, /*nIter*/ 1);
    if (!wide) throw std::runtime_error("Morpher: fast sweeping could not extend a signed distance field");
    return wide;
}

/// Removes dust from the blended field before its surface is rebuilt: face-connected pieces of the
/// interior (values < 0) with fewer than `minVoxels` voxels, apart from the largest, become outside
/// (`outside`); bubbles, pieces of the exterior with fewer than `minVoxels` voxels enclosed by the
/// interior (no face neighbour in the background), become inside (-`outside`). Returns the count.
size_t dropIslands(openvdb::FloatGrid& values, int minVoxels, float outside)
{
    if (minVoxels <= 0) return 0;
    // Interior: every negative value, active or not (after narrowBand the deep interior is inactive
    // tiles). Exterior candidates: positive active values only (the far exterior is background).
    auto pieces = [&values](bool negative) {
        openvdb::BoolGrid mask(false);
        auto acc = mask.getAccessor();
        for (auto it = values.cbeginValueAll(); it; ++it) {
            if ((*it < 0.0f) != negative || (!negative && !it.isValueOn())) continue;
            if (it.isVoxelValue()) acc.setValueOn(it.getCoord(), true);
            else mask.sparseFill(it.getBoundingBox(), true, true);
        }
        std::vector<openvdb::BoolGrid::Ptr> out;
        openvdb::tools::segmentActiveVoxels(mask, out); // largest first
        return out;
    };
    size_t changed = 0;
    auto acc = values.getAccessor();
    auto set = [&acc](const openvdb::BoolGrid& piece, float value) {
        for (auto it = piece.cbeginValueOn(); it; ++it)
            for (auto c = it.getBoundingBox().begin(); c; ++c) acc.setValue(*c, value);
    };
    const std::vector<openvdb::BoolGrid::Ptr> islands = pieces(true);
    for (size_t i = 1; i < islands.size(); ++i)
        if (islands[i]->activeVoxelCount() < openvdb::Index64(minVoxels)) {
            set(*islands[i], outside);
            ++changed;
        }
    for (const openvdb::BoolGrid::Ptr& gap : pieces(false)) {
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

/// Makes `sdf` a level set of half width `width` (world units), in place: voxels at or beyond it
/// become inactive with value +/- width, and constant leaves collapse into tiles.
void narrowBand(openvdb::FloatGrid& sdf, float width)
{
    openvdb::tree::LeafManager<FloatTree> leaves(sdf.tree());
    leaves.foreach([width](FloatTree::LeafNodeType& leaf, size_t) {
        for (auto it = leaf.beginValueAll(); it; ++it)
            if (!(std::abs(*it) < width) || !it.isValueOn()) {
                it.setValue(*it < 0.0f ? -width : width);
                it.setValueOff();
            }
    });
    for (auto it = sdf.tree().beginValueOn(); it; ++it) // active tiles, if any: deep inside or outside
        if (!it.isVoxelValue()) {
            it.setValue(*it < 0.0f ? -width : width);
            it.setValueOff();
        }
    openvdb::tools::changeLevelSetBackground(sdf.tree(), width);
    openvdb::tools::pruneLevelSet(sdf.tree());
}

template <typename Sampler>
struct Resampler {
    const VolumeSet& source;
    const VolumeSet& target;
    const openvdb::FloatGrid* sdfSource; ///< sdf mode: the extended distances
    const openvdb::FloatGrid* sdfTarget;
    float tauDensity, tauColor, tauSdf;
    Vec3f background;
    bool sdfMode;
    float outside; ///< sdf mode: blended distances at or above this are far outside (dropped)

    /// Fills one output leaf pair: `value` gets the blended density, or in sdf mode the blended
    /// signed distance. Returns false when the leaf holds nothing.
    bool operator()(const detail::WarpLeaf& w, FloatTree::LeafNodeType& value, Vec3STree::LeafNodeType& color) const
    {
        auto ds = source.density->getConstAccessor();
        auto dt = target.density->getConstAccessor();
        auto cs = source.color->getConstAccessor();
        auto ct = target.color->getConstAccessor();
        std::unique_ptr<openvdb::FloatGrid::ConstAccessor> ss, st;
        if (sdfMode) {
            ss = std::make_unique<openvdb::FloatGrid::ConstAccessor>(sdfSource->getConstAccessor());
            st = std::make_unique<openvdb::FloatGrid::ConstAccessor>(sdfTarget->getConstAccessor());
        }
        bool any = false;
        for (openvdb::Index n = 0; n < 512; ++n) {
            const openvdb::Vec3R ps(w.source[n]), pt(w.target[n]);
            const float a = Sampler::sample(ds, ps);
            const float b = Sampler::sample(dt, pt);
            if (sdfMode) {
                // Distances are real over both objects' box; beyond it both are clamped to positive
                // values (outside), so the blend's sign is right wherever either side is defined.
                const float d = (1.0f - tauSdf) * Sampler::sample(*ss, ps) + tauSdf * Sampler::sample(*st, pt);
                value.setValueOn(n, d);
                any = any || d < outside;
            } else {
                const float d = (1.0f - tauDensity) * a + tauDensity * b;
                if (!(d > kEmpty)) continue;
                value.setValueOn(n, d);
                any = true;
            }
            // Colour weighted by each side's density, so an empty side contributes no colour.
            const float wa = (1.0f - tauColor) * std::max(a, 0.0f), wb = tauColor * std::max(b, 0.0f);
            Vec3f c = background;
            if (wa + wb > 0.0f) {
                const Vec3f ca = wa > 0.0f ? Sampler::sample(cs, ps) : Vec3f(0.0f);
                const Vec3f cb = wb > 0.0f ? Sampler::sample(ct, pt) : Vec3f(0.0f);
                c = (wa * ca + wb * cb) / (wa + wb);
            }
            color.setValueOn(n, c);
        }
        return any;
    }
};

} // namespace

Morpher::Morpher(VolumeSet source, VolumeSet target, std::vector<FeaturePairSpec> pairs, WarpSpec warp,
                 BlendSpec blend, MorphOptions options)
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
            // A margin for warped points that leave the box: an eighth of its size, at least 8 voxels.
            const Coord dim = box.dim();
            const int margin = std::max(8, std::max({dim.x(), dim.y(), dim.z()}) / 8);
            box.expand(margin);
            mWideSdfSource = extendedDistances(*mSource.sdf, box);
            mWideSdfTarget = extendedDistances(*mTarget.sdf, box);
        } else {
            mWideSdfSource = mSource.sdf;
            mWideSdfTarget = mTarget.sdf;
        }
    }
}

CoordBBox Morpher::candidateBounds(double t) const
{
    const CoordBBox s = mSourceBlocks->bounds(), d = mTargetBlocks->bounds();
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

VolumeSet Morpher::frameOverBox(double t, const CoordBBox& box, double tolerance, MorphStats* stats) const
{
    return run(t, box, false, tolerance, stats, nullptr);
}

VolumeSet Morpher::run(double t, const CoordBBox& box, bool prune, double tolerance, MorphStats* stats,
                       Interrupter* interrupter) const
{
    const double voxel = mSource.voxelSize();
    const InverseWarp warp(mPairs, mWarp, t, 1.0 / voxel);
    const detail::AdaptiveWarp adaptive(warp, tolerance, mWarp.epsilon / voxel);
    const detail::Occupancy* occS = prune ? mSourceBlocks.get() : nullptr;
    const detail::Occupancy* occT = prune ? mTargetBlocks.get() : nullptr;
    const float tauD = float(mBlend.density.evaluate(t)), tauC = float(mBlend.color.evaluate(t));
    const float tauS = float(mBlend.sdf.evaluate(t));
    const bool sdfMode = mBlend.mode == BlendMode::Sdf;
    const float outside = sdfMode ? std::min(mSource.sdf->background(), mTarget.sdf->background()) : 0.0f;
    const Vec3f background = (1.0f - tauC) * mSource.color->background() + tauC * mTarget.color->background();

    std::mutex collect;
    std::vector<std::pair<FloatTree::LeafNodeType*, Vec3STree::LeafNodeType*>> leaves;
    // The memory guard: a warp that blows the shape up (a pair scaling by 100, say) would
    // otherwise fill the machine's memory leaf by leaf.
    const uint64_t limit = mOptions.memoryLimitBytes ? mOptions.memoryLimitBytes : defaultMemoryLimitBytes();
    const size_t maxLeaves = size_t(std::max<uint64_t>(1, limit / kMorphBytesPerLeaf));
    auto each = [&](auto resampler) {
        return [&, resampler](const detail::WarpLeaf& w) {
            auto density = std::make_unique<FloatTree::LeafNodeType>(w.origin, 0.0f, false);
            auto color = std::make_unique<Vec3STree::LeafNodeType>(w.origin, background, false);
            if (!resampler(w, *density, *color)) return;
            std::lock_guard<std::mutex> lock(collect);
            if (leaves.size() >= maxLeaves) { // the leaves kept so far are freed below
                char text[300];
                std::snprintf(text, sizeof text,
                              "the in-between at t = %.4f needs more than the memory limit of %.1f GiB (over %zu "
                              "blocks of 8^3 voxels); use a larger voxel size, check the feature pairs' scales, or "
                              "raise --memory-limit (default: half the machine's memory)",
                              t, double(limit) / double(1ull << 30), maxLeaves);
                throw UserError(SourceLocation{"morph"}, text);
            }
            leaves.emplace_back(density.release(), color.release());
        };
    };
    detail::AdaptiveWarpStats warpStats;
    try {
        if (mOptions.sampling == MorphOptions::Sampling::Triquadratic)
            adaptive.forEachLeaf(box, occS, occT,
                                 each(Resampler<openvdb::tools::QuadraticSampler>{mSource, mTarget, mWideSdfSource.get(),
                                                                                  mWideSdfTarget.get(), tauD, tauC, tauS, background,
                                                                                  sdfMode, outside}),
                                 &warpStats, interrupter);
        else
            adaptive.forEachLeaf(box, occS, occT,
                                 each(Resampler<openvdb::tools::BoxSampler>{mSource, mTarget, mWideSdfSource.get(),
                                                                            mWideSdfTarget.get(), tauD, tauC, tauS, background, sdfMode,
                                                                            outside}),
                                 &warpStats, interrupter);
    } catch (...) {
        for (auto& [density, color] : leaves) {
            delete density;
            delete color;
        }
        throw;
    }

    VolumeSet out;
    openvdb::FloatGrid::Ptr values =
        openvdb::FloatGrid::create(sdfMode ? std::max(mSource.sdf->background(), mTarget.sdf->background()) : 0.0f);
    out.color = openvdb::Vec3SGrid::create(background);
    for (auto& [value, color] : leaves) {
        values->tree().addLeaf(value);
        out.color->tree().addLeaf(color);
    }
    values->setTransform(mSource.density->transform().copy());
    if (sdfMode) {
        // The blend of two warped distances has the right zero set but is no distance field. Keep
        // the part that can lie within the band (|blend| < 3 bands: its gradient is at most the
        // warp's local stretch, taken to be under 3), drop dust, redistance by fast sweeping
        // (which keeps the blend's signs; a rebuild through a mesh and its scanline flood fill
        // flipped single voxels where two sheets nearly touch), keep the band, and derive the fog.
        values->setGridClass(openvdb::GRID_LEVEL_SET);
        narrowBand(*values, 3.0f * outside);
        dropIslands(*values, mBlend.minIslandVoxels, 3.0f * outside);
        out.sdf = openvdb::tools::sdfToSdf(*values, 0.0f, 1);
        narrowBand(*out.sdf, outside);
        out.sdf->setName(kSdfGridName);
        out.sdf->setGridClass(openvdb::GRID_LEVEL_SET);
        out.density = fogFromLevelSet(*out.sdf, 1.5f * float(voxel));
    } else {
        out.density = values;
        openvdb::tools::prune(out.density->tree()); // leaves of constant interior collapse into tiles
    }
    openvdb::tools::prune(out.color->tree());
    out.color->setTransform(mSource.density->transform().copy());
    out.density->setName(kDensityGridName);
    out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    out.color->setName(kColorGridName);
    out.color->setVectorType(openvdb::VEC_INVARIANT);

    if (stats) {
        stats->maxWarpErrorVoxels = warpStats.maxErrorVoxels;
        stats->exactEvaluations = warpStats.exactEvaluations;
        stats->candidateLeaves = warpStats.leaves;
        stats->outputLeaves = leaves.size();
        stats->activeVoxels = out.density->activeVoxelCount();
    }
    return out;
}

} // namespace volmorph
