#include "blend/DensityBlend.h"

#include "blend/BlendTime.h"
#include "blend/ColorBlend.h"
#include "blend/ExtraGrids.h"
#include "blend/Sample.h"
#include "blend/UniformBlocks.h"
#include "blend/VelocityBlend.h"
#include "blend/VelocityReach.h"
#include "blend/WithSampler.h"

#include <volmorph/Schedule.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Prune.h>

#include <optional>

namespace volmorph::detail {
namespace {

/// Fills one output leaf pair with the blended density and colour.
template <typename Sampler>
struct Resampler {
    const VolumeSet& source;
    const VolumeSet& target;
    const BlendTime& densityTime; ///< tau at each voxel (uniform without a timing)
    const BlendTime& colorTime;
    Vec3f background;

    struct Uniform {
        float density;
        Vec3f color;
    };
    /// The leaf's one density and colour, when all its points warp into blocks of one value on
    /// both sides (the colour's only where that side weighs); nothing when some point may not.
    std::optional<Uniform> uniform(const WarpLeaf& w) const
    {
        if (!densityTime.uniform()) return std::nullopt; // each voxel has its own tau
        const float tauDensity = densityTime.atAll().tau, tauColor = colorTime.atAll().tau;
        const openvdb::CoordBBox boxS = warpedBox(w.s), boxT = warpedBox(w.t);
        auto ds = source.density->getConstAccessor();
        auto dt = target.density->getConstAccessor();
        float a, b;
        if (!uniformOver(ds, boxS, a) || !uniformOver(dt, boxT, b)) return std::nullopt;
        Uniform u{(1.0f - tauDensity) * a + tauDensity * b, background};
        if (!(u.density > kEmpty)) return u;
        // ColorBlend's mix, of each side's one colour.
        const float wa = (1.0f - tauColor) * std::max(a, 0.0f), wb = tauColor * std::max(b, 0.0f);
        if (!(wa + wb > 0.0f)) return u;
        Vec3f ca(0.0f), cb(0.0f);
        auto cs = source.color->getConstAccessor();
        auto ct = target.color->getConstAccessor();
        if (wa > 0.0f && !uniformOver(cs, boxS, ca)) return std::nullopt;
        if (wb > 0.0f && !uniformOver(ct, boxT, cb)) return std::nullopt;
        u.color = (wa * ca + wb * cb) / (wa + wb);
        return u;
    }

    /// Returns false when the leaf holds nothing. a, b: each side's density at the voxels'
    /// warped points, where the output is kept.
    bool operator()(const WarpLeaf& w, OutputLeaves::ValueLeaf& value,
                    OutputLeaves::ColorLeaf& color, float a[512], float b[512]) const
    {
        auto ds = source.density->getConstAccessor();
        auto dt = target.density->getConstAccessor();
        ColorBlend<Sampler> blend(source, target, colorTime.atAll().tau, background);
        const bool timed = !densityTime.uniform();
        float tauDensity = densityTime.atAll().tau;
        bool any = false;
        for (openvdb::Index n = 0; n < 512; ++n) {
            const openvdb::Vec3R ps(w.source(n)), pt(w.target(n));
            a[n] = sample<Sampler>(ds, ps);
            b[n] = sample<Sampler>(dt, pt);
            if (timed) {
                const Delay delay = densityTime.delayAt(
                    (w.origin + OutputLeaves::ValueLeaf::offsetToLocalCoord(n)).asVec3d());
                tauDensity = densityTime.fromDelay(delay).tau;
                blend.setTau(colorTime.fromDelay(delay).tau);
            }
            const float d = (1.0f - tauDensity) * a[n] + tauDensity * b[n];
            if (!(d > kEmpty)) continue;
            value.setValueOn(n, d);
            any = true;
            color.setValueOn(n, blend(ps, pt, a[n], b[n]));
        }
        return any;
    }
};

template <typename Sampler>
class DensityBlend final : public TwoSidedBlend {
public:
    explicit DensityBlend(const BlendSetup& setup) : TwoSidedBlend(setup) {}

    BlendedFrame frame(const BlendRequest& r, OutputLeaves& leaves) const override
    {
        const openvdb::math::Transform& xform = mSource.density->transform();
        const BlendTime densityTime(mSpec.density, r.t, r.localTime, xform);
        const BlendTime colorTime(mSpec.color, r.t, r.localTime, xform);
        const Resampler<Sampler> resample{mSource, mTarget, densityTime, colorTime,
                                          leaves.background()};
        const ExtraGrids extras(mSource, mTarget, mSpec, r.t, r.localTime);
        const VelocityBlend velocity(*r.warp, r.velocityScale, densityTime);
        BlendedFrame out;
        r.warp->forEachLeaf(
            r.box, r.sourceBlocks, r.targetBlocks,
            [&](const WarpLeaf& w) {
                // A uniform interior is one tile (without `vel`: any velocity transports a
                // uniform density), unless carried grids need the leaf's samples.
                if (const auto u = extras.empty() ? resample.uniform(w) : std::nullopt) {
                    if (u->density > kEmpty) leaves.uniformTile(w.origin, u->density, u->color);
                    return;
                }
                auto [density, color] = leaves.make(w.origin, 0.0f);
                float a[512], b[512];
                if (!resample(w, *density, *color, a, b)) return;
                ExtraLeaves e = extras.make(w.origin);
                extras.fill<Sampler>(density->getValueMask(), WarpedPoints{w}, e);
                if (velocity.enabled())
                    e.velocity = velocity.leaf(w.origin, density->getValueMask(), a, b);
                leaves.keep(std::move(density), std::move(color), std::move(e));
            },
            &out.warp, r.interrupter);
        out.grids.density = openvdb::FloatGrid::create(0.0f);
        out.grids.color = openvdb::Vec3SGrid::create(leaves.background());
        out.keptLeaves = leaves.size();
        out.velocityInterpolated = velocity.interpolatedCubes();
        out.velocityExact = velocity.exactCubes();
        ExtraGrids::Outputs carried = extras.outputs();
        if (velocity.enabled()) {
            out.grids.velocity = openvdb::Vec3SGrid::create(Vec3f(0.0f));
            carried.trees.velocity = &out.grids.velocity->tree();
        }
        leaves.moveInto(out.grids.density->tree(), out.grids.color->tree(), 0.0f, carried.trees);
        out.grids.extras = std::move(carried.grids);
        if (out.grids.velocity)
            VelocityReach(velocity, r.velocityReachSeconds, mSource.voxelSize())
                .grow(*out.grids.velocity, nullptr);
        // Leaves of constant interior collapse into tiles.
        openvdb::tools::prune(out.grids.density->tree());
        return out;
    }
};

} // namespace

std::unique_ptr<const BlendMethod> makeDensityBlend(const BlendSetup& setup)
{
    return withSampler<DensityBlend>(setup);
}

} // namespace volmorph::detail
