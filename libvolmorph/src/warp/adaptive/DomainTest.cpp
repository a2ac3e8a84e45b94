#include "warp/adaptive/DomainTest.h"

#include "warp/adaptive/Context.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

CoordBBox widened(const Vec3d& lo, const Vec3d& hi, double margin)
{
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e9, 1.0e9)); };
    return CoordBBox(
        Coord(clampInt(std::floor(lo.x() - margin)), clampInt(std::floor(lo.y() - margin)),
              clampInt(std::floor(lo.z() - margin))),
        Coord(clampInt(std::ceil(hi.x() + margin)), clampInt(std::ceil(hi.y() + margin)),
              clampInt(std::ceil(hi.z() + margin))));
}

void affineImage(const InverseWarp::Affine& a, const Vec3d& o, double size, Vec3d& lo, Vec3d& hi)
{
    lo = hi = a.apply(o);
    for (int c = 0; c < 3; ++c) {
        const Vec3d step = a.col[c] * size;
        for (int k = 0; k < 3; ++k) (step[k] < 0 ? lo : hi)[k] += step[k];
    }
}

bool touches(const Occupancy* occ, const Vec3d& lo, const Vec3d& hi, double margin)
{
    return occ && occ->anyIn(widened(lo, hi, margin));
}

bool hullMayTouch(const CoordBBox& cube, const std::vector<InverseWarp::Affine>& source,
                  const std::vector<InverseWarp::Affine>& target, const Occupancy* sourceBlocks,
                  const Occupancy* targetBlocks)
{
    const double size = cube.dim().x();
    Vec3d slo(std::numeric_limits<double>::max()), shi(-slo), tlo(slo), thi(-slo);
    for (size_t i = 0; i < source.size(); ++i) {
        Vec3d a, c;
        affineImage(source[i], cube.min().asVec3d(), size, a, c);
        slo = minComponent(slo, a);
        shi = maxComponent(shi, c);
        affineImage(target[i], cube.min().asVec3d(), size, a, c);
        tlo = minComponent(tlo, a);
        thi = maxComponent(thi, c);
    }
    return touches(sourceBlocks, slo, shi, kSamplerReach) ||
           touches(targetBlocks, tlo, thi, kSamplerReach);
}

// The domain, before any voxel. With every pair far the interpolant is B + I[G] / I[W], and
// I[G] / I[W] is a convex combination of the corners' rho_k = G_k / W_k: the image lies within
// B(cube) + hull(rho_k), widened by the bound. Otherwise p = B + rho with |rho| <= rhoMax.
bool AdaptiveWarp::mayTouch(WarpContext& ctx, const Coord& origin, int size) const
{
    const double h = size, rhoMax = ctx.rhoMax, boundAllFar = ctx.boundAllFar;
    const Vec3d o = origin.asVec3d();
    const InverseWarp::Affine& bS = mSource[ctx.dominant];
    const InverseWarp::Affine& bT = mTarget[ctx.dominant];
    // The corners' residuals rho_k = p_k - B(x_k), each side (their box from analyze()).
    Vec3d rsLo(-rhoMax), rsHi(rhoMax), rtLo(-rhoMax), rtHi(rhoMax);
    if (ctx.cornersOk) {
        rsLo = ctx.rhoLo[0];
        rsHi = ctx.rhoHi[0];
        rtLo = ctx.rhoLo[1];
        rtHi = ctx.rhoHi[1];
    }
    Vec3d sLo, sHi, tLo, tHi;
    affineImage(bS, o, h, sLo, sHi);
    affineImage(bT, o, h, tLo, tHi);
    // Where the corners themselves land: a cube whose corners' box touches an occupied block is
    // kept without a second test on its filled points.
    ctx.coreTouches =
        ctx.cornersOk && (touches(ctx.source, sLo + rsLo, sHi + rsHi, kSamplerReach) ||
                          touches(ctx.target, tLo + rtLo, tHi + rtHi, kSamplerReach));
    if (ctx.coreTouches) return true;
    if (ctx.cornersOk && boundAllFar < rhoMax) {
        const double margin = kSamplerReach + boundAllFar;
        return touches(ctx.source, sLo + rsLo, sHi + rsHi, margin) ||
               touches(ctx.target, tLo + rtLo, tHi + rtHi, margin);
    }
    const double margin = kSamplerReach + rhoMax;
    return touches(ctx.source, sLo, sHi, margin) || touches(ctx.target, tLo, tHi, margin);
}

} // namespace volmorph::detail
