// The morph's orchestration: the frame's domain, its warp, the output leaves under the memory
// guard, and the blend method that fills them (src/blend/).
#include <volmorph/Morph.h>
#include <volmorph/Schedule.h>
#include <volmorph/Warp.h>

#include "blend/BlendMethod.h"
#include "blend/ExtraGrids.h"
#include "warp/AdaptiveWarp.h"
#include "warp/TimedWarp.h"

#include <volmorph/core/MemoryLimit.h>

#include <openvdb/math/Mat3.h>
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace volmorph {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

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

/// The grids' names, classes and transform, and the stats, common to every method.
void finish(VolumeSet& out, const openvdb::math::Transform& xform, MorphStats* stats,
            const detail::BlendedFrame& frame)
{
    openvdb::tools::prune(out.color->tree());
    out.color->setTransform(xform.copy());
    out.density->setTransform(xform.copy());
    out.density->setName(kDensityGridName);
    out.density->setGridClass(openvdb::GRID_FOG_VOLUME);
    out.color->setName(kColorGridName);
    out.color->setVectorType(openvdb::VEC_INVARIANT);
    if (out.sdf) out.sdf->setName(kSdfGridName);
    if (out.velocity) {
        out.velocity->setTransform(xform.copy());
        out.velocity->setName(kVelocityGridName);
        out.velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    }
    for (auto& [name, grid] : out.extras) {
        grid->pruneGrid();
        grid->setTransform(xform.copy());
    }
    if (stats) {
        stats->maxWarpErrorVoxels = frame.warp.maxErrorVoxels;
        stats->exactEvaluations = frame.warp.exactEvaluations;
        stats->candidateLeaves = frame.warp.leaves;
        stats->outputLeaves = frame.keptLeaves;
        stats->activeVoxels = out.density->activeVoxelCount();
        stats->blendSamples = frame.blendSamples;
        stats->velocityInterpolated = frame.velocityInterpolated;
        stats->velocityExact = frame.velocityExact;
    }
}

} // namespace

Morpher::Morpher(VolumeSet source, VolumeSet target, std::vector<FeaturePairSpec> pairs,
                 WarpSpec warp, BlendSpec blend, MorphOptions options)
    : mSource(std::move(source)), mTarget(std::move(target)), mPairs(std::move(pairs)), mWarp(warp),
      mBlend(std::move(blend)), mOptions(options)
{
    if (!mSource.density || !mTarget.density || !mSource.color || !mTarget.color)
        throw std::invalid_argument("Morpher: source and target need density and Cd grids");
    if (!(mSource.density->transform() == mTarget.density->transform()))
        throw std::invalid_argument("Morpher: source and target must share one transform");
    if (!mOptions.memoryLimitBytes) mOptions.memoryLimitBytes = defaultMemoryLimitBytes();
    detail::ExtraGrids::check(mSource, mTarget, mBlend);
    mSourceBlocks = std::make_shared<const detail::Occupancy>(mSource.density->tree());
    mTargetBlocks = std::make_shared<const detail::Occupancy>(mTarget.density->tree());
    const detail::BlendSetup setup{mSource,
                                   mTarget,
                                   mBlend,
                                   mOptions.sampling == MorphOptions::Sampling::Triquadratic
                                       ? detail::Interpolation::Triquadratic
                                       : detail::Interpolation::Trilinear,
                                   mPairs.size(),
                                   mPairs.empty() ? candidateBounds(0.0) : CoordBBox(),
                                   mOptions.memoryLimitBytes,
                                   mOptions.setupInterrupter,
                                   &mOptions.influences};
    mMethod = detail::makeBlendMethod(setup);
    tabulate();
}

bool Morpher::timed() const
{
    return mOptions.localTime && mOptions.localTime->active();
}

void Morpher::tabulate()
{
    mTauTable.reset();
    if (!timed() || mPairs.empty()) return;
    // Sampled over where the output can be, at either end and half way.
    CoordBBox region = boundsAt(0.0);
    region.expand(boundsAt(0.5));
    region.expand(boundsAt(1.0));
    mTauTable = std::make_shared<const detail::TauTable>(detail::TauTable::make(
        mPairs, mWarp, 1.0 / mSource.voxelSize(), region, mWarp.toleranceVoxels));
}

Morpher Morpher::withPairs(std::vector<FeaturePairSpec> pairs) const
{
    // The variational method does not use the pairs; the others set up apart with none.
    if (mBlend.mode != BlendMode::Variational && (pairs.empty() || mPairs.empty()))
        return Morpher(mSource, mTarget, std::move(pairs), mWarp, mBlend, mOptions);
    Morpher other(*this);
    other.mPairs = std::move(pairs);
    other.tabulate();
    return other;
}

Morpher Morpher::withTiming(std::shared_ptr<const LocalTime> localTime) const
{
    Morpher other(*this);
    other.mOptions.localTime = std::move(localTime);
    other.tabulate();
    return other;
}

CoordBBox Morpher::candidateBounds(double t) const
{
    if (!mTauTable) return boundsAt(t);
    // Under a timing a place can be at any local time: every level's.
    CoordBBox box;
    for (const double tau : mTauTable->levels) box.expand(boundsAt(tau));
    return box;
}

CoordBBox Morpher::boundsAt(double t) const
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

VolumeSet Morpher::run(double t, const CoordBBox& box, bool prune, double tolerance,
                       MorphStats* stats, Interrupter* interrupter) const
{
    const double unit = 1.0 / mSource.voxelSize();
    const InverseWarp warp(mPairs, mWarp, t, unit);
    std::unique_ptr<const detail::FrameWarp> frameWarp;
    if (mTauTable)
        frameWarp = std::make_unique<const detail::TimedWarp>(
            mPairs, mWarp, unit, *mTauTable, *mOptions.localTime, mSource.density->transform(), t,
            tolerance);
    else
        frameWarp = std::make_unique<const detail::PlainWarp>(warp, tolerance);
    detail::BlendRequest request;
    request.t = t;
    request.box = box;
    request.prune = prune;
    request.toleranceVoxels = tolerance;
    request.warp = frameWarp.get();
    request.sourceBlocks = prune ? mSourceBlocks.get() : nullptr;
    request.targetBlocks = prune ? mTargetBlocks.get() : nullptr;
    request.interrupter = interrupter;
    if (mOptions.secondsPerUnitT > 0.0)
        request.velocityScale = mSource.voxelSize() / mOptions.secondsPerUnitT;
    request.velocityReachSeconds = mOptions.velocityReachSeconds;
    request.localTime = mOptions.localTime.get();
    const float tauColor = float(scheduleValue(mBlend.color, t));
    detail::OutputLeaves leaves(
        t, mOptions.memoryLimitBytes, residentBytes(),
        (mBlend.mode == BlendMode::Density ? kDensityBytesPerLeaf : kMorphBytesPerLeaf) +
            detail::ExtraGrids::bytesPerLeaf(mSource, mTarget) +
            (request.velocityScale > 0.0 ? kVelocityBytesPerLeaf : 0),
        detail::blendedColorBackground(mSource, mTarget, tauColor));
    detail::BlendedFrame frame = mMethod->frame(request, leaves);
    finish(frame.grids, mSource.density->transform(), stats, frame);
    return std::move(frame.grids);
}

} // namespace volmorph
