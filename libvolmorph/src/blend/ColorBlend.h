// Colour at a warped point of both sides, weighted by each side's density (premultiplied), so an
// empty side contributes no colour. Both blend methods colour their output with it.
#pragma once

#include "blend/Sample.h"

#include <volmorph/VolumeSet.h>
#include <volmorph/core/Math.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <type_traits>

namespace volmorph::detail {

template <typename Sampler>
class ColorBlend {
public:
    /// tauColor: the colour schedule's weight of the target; background: the output's.
    ColorBlend(const VolumeSet& source, const VolumeSet& target, float tauColor, const Vec3f& bg)
        : mSource(source.color->getConstAccessor()), mTarget(target.color->getConstAccessor()),
          mTau(tauColor), mBackground(bg)
    {
    }
    /// The colour schedule's tau for what follows (a timing gives each voxel its own).
    void setTau(float tauColor) { mTau = tauColor; }
    /// ps, pt: the warped points (index space); a, b: the densities there.
    Vec3f operator()(const openvdb::Vec3R& ps, const openvdb::Vec3R& pt, float a, float b)
    {
        return mix(
            a, b, [&] { return Vec3f(sample<Sampler>(mSource, ps)); },
            [&] { return Vec3f(sample<Sampler>(mTarget, pt)); });
    }
    /// The same at voxel ijk of both sides (the identity warp). Trilinear weights there are 1 and
    /// 0, so BoxSampler's value is the voxel's own: read it directly.
    Vec3f atVoxel(const openvdb::Coord& ijk, float a, float b)
    {
        if constexpr (!std::is_same_v<Sampler, openvdb::tools::BoxSampler>) {
            const openvdb::Vec3R p(Vec3f(float(ijk.x()), float(ijk.y()), float(ijk.z())));
            return (*this)(p, p, a, b);
        } else {
            return mix(
                a, b, [&] { return mSource.getValue(ijk); }, [&] { return mTarget.getValue(ijk); });
        }
    }

private:
    /// The density-weighted mix; each side's colour is read only when its weight is positive.
    template <typename ReadS, typename ReadT>
    Vec3f mix(float a, float b, const ReadS& readSource, const ReadT& readTarget) const
    {
        const float wa = (1.0f - mTau) * std::max(a, 0.0f), wb = mTau * std::max(b, 0.0f);
        if (!(wa + wb > 0.0f)) return mBackground;
        const Vec3f ca = wa > 0.0f ? readSource() : Vec3f(0.0f);
        const Vec3f cb = wb > 0.0f ? readTarget() : Vec3f(0.0f);
        return (wa * ca + wb * cb) / (wa + wb);
    }

    openvdb::Vec3SGrid::ConstAccessor mSource, mTarget;
    float mTau;
    Vec3f mBackground;
};

} // namespace volmorph::detail
