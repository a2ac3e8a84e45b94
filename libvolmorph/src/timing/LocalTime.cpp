#include <volmorph/LocalTime.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace volmorph {
namespace {

/// The ramp's rounded ends, as a fraction of its length.
constexpr double kRound = 0.1;
/// The ramp's slope in its linear middle: 1 / (1 - kRound), so that it rises by 1 in all.
constexpr double kSlope = 1.0 / (1.0 - kRound);

/// s(u): 0 for u <= 0, 1 for u >= 1, quadratic on [0, kRound] and [1 - kRound, 1], linear
/// between with slope kSlope (C1); its derivative into `slope`.
double ramp(double u, double& slope)
{
    const double a = kSlope / (2.0 * kRound);
    if (u <= 0.0 || u >= 1.0) {
        slope = 0.0;
        return u <= 0.0 ? 0.0 : 1.0;
    }
    if (u < kRound) {
        slope = 2.0 * a * u;
        return a * u * u;
    }
    if (u > 1.0 - kRound) {
        const double v = 1.0 - u;
        slope = 2.0 * a * v;
        return 1.0 - a * v * v;
    }
    slope = kSlope;
    return kSlope * (u - 0.5 * kRound);
}

/// A region's weight from its signed distance: 1 inside, smoothstep down to 0 at `softness`
/// outside; its derivative along the distance into `slope`.
double weight(double distance, double softness, double& slope)
{
    slope = 0.0;
    if (distance <= 0.0) return 1.0;
    if (!(distance < softness)) return 0.0;
    const double u = distance / softness;
    slope = -6.0 * u * (1.0 - u) / softness;
    return 1.0 - u * u * (3.0 - 2.0 * u);
}

/// The quadratic B-spline's three weights at offset u in [-0.5, 0.5] from the nearest sample,
/// and their derivatives.
void bspline(double u, double w[3], double dw[3])
{
    w[0] = 0.5 * (0.5 - u) * (0.5 - u);
    w[1] = 0.75 - u * u;
    w[2] = 0.5 * (0.5 + u) * (0.5 + u);
    dw[0] = u - 0.5;
    dw[1] = -2.0 * u;
    dw[2] = u + 0.5;
}

/// The region's signed distance at world point x and its exact gradient, from the quadratic
/// B-spline of its voxels (C1, so that the delay is; it smooths the distance by about an eighth
/// of a voxel times the surface's curvature in voxels).
double distanceAt(const openvdb::FloatGrid& sdf, const Vec3d& x, Vec3d& gradient)
{
    const Vec3d p = sdf.worldToIndex(x);
    const openvdb::Coord c(int(std::floor(p.x() + 0.5)), int(std::floor(p.y() + 0.5)),
                           int(std::floor(p.z() + 0.5)));
    double w[3][3], dw[3][3];
    for (int k = 0; k < 3; ++k) bspline(p[k] - c[k], w[k], dw[k]);
    auto acc = sdf.getConstAccessor();
    double value = 0.0;
    Vec3d g(0.0);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                const double v = acc.getValue(c.offsetBy(i - 1, j - 1, k - 1));
                value += w[0][i] * w[1][j] * w[2][k] * v;
                g += Vec3d(dw[0][i] * w[1][j] * w[2][k], w[0][i] * dw[1][j] * w[2][k],
                           w[0][i] * w[1][j] * dw[2][k]) *
                     v;
            }
    gradient = g / sdf.voxelSize()[0];
    return value;
}

} // namespace

LocalTime::LocalTime(const TimingSettings& settings, std::vector<TimingRegion> regions)
    : mSpread(settings.spread), mSweep(settings.sweep), mRegions(std::move(regions))
{
    if (!(mSpread >= 0.0 && mSpread < 1.0))
        throw std::invalid_argument("LocalTime: the spread must lie in [0, 1)");
    if (mSweep && !(mSweep->length > 0.0))
        throw std::invalid_argument("LocalTime: the sweep's length must be positive");
    for (const TimingRegion& r : mRegions) {
        if (!r.sdf || !(r.start >= 0.0 && r.start <= mSpread) || !(r.softness >= 0.0))
            throw std::invalid_argument(
                "LocalTime: a region needs an sdf, a start in [0, spread] and softness >= 0");
        // Beyond its band a level set reads its background: the fade must end within it.
        if (double(r.sdf->background()) < r.softness)
            throw std::invalid_argument("LocalTime: a region's level set must reach its softness");
    }
    if (mSweep) mSweep->direction = mSweep->direction.unit();
}

Delay LocalTime::delay(const Vec3d& x) const
{
    Delay out;
    if (mSpread == 0.0) return out;
    if (mSweep) {
        const double u = (x - mSweep->origin).dot(mSweep->direction) / mSweep->length;
        double slope;
        out.d = mSpread * ramp(u, slope);
        out.gradient = mSweep->direction * (mSpread * slope / mSweep->length);
    }
    for (const TimingRegion& r : mRegions) {
        Vec3d g;
        const double distance = distanceAt(*r.sdf, x, g);
        double slope;
        const double w = weight(distance, r.softness, slope);
        // d' = (1 - w) d + w start: grad d' = (1 - w) grad d + (start - d) grad w.
        out.gradient = out.gradient * (1.0 - w) + g * ((r.start - out.d) * slope);
        out.d = (1.0 - w) * out.d + w * r.start;
    }
    return out;
}

LocalTau LocalTime::fromDelay(const Delay& delay, double t) const
{
    LocalTau out;
    const double scale = 1.0 / (1.0 - mSpread);
    const double raw = (t - delay.d) * scale;
    if (raw <= 0.0 || raw >= 1.0) {
        out.tau = raw <= 0.0 ? 0.0 : 1.0;
        out.dt = 0.0;
        return out;
    }
    out.tau = raw;
    out.dt = scale;
    out.gradient = delay.gradient * -scale;
    return out;
}

LocalTau LocalTime::at(const Vec3d& x, double t) const
{
    if (mSpread == 0.0) return LocalTau{t, 1.0, Vec3d(0.0)};
    return fromDelay(delay(x), t);
}

bool LocalTime::clampedWithin(const Vec3d& x, double radius, double t, double& tau) const
{
    if (mSpread == 0.0) return false;
    const double d = delay(x).d, reach = maxDelayGradient() * radius;
    if (!(t - (d - reach) <= 0.0) && !(t - (d + reach) >= 1.0 - mSpread)) return false;
    tau = t - (d - reach) <= 0.0 ? 0.0 : 1.0;
    return true;
}

double LocalTime::maxDelayGradient() const
{
    double g = mSweep ? mSpread * kSlope / mSweep->length : 0.0;
    for (const TimingRegion& r : mRegions) {
        if (r.softness == 0.0) return std::numeric_limits<double>::infinity();
        g += 1.5 * mSpread / r.softness; // smoothstep's steepest slope, times |start - d|
    }
    return g;
}

} // namespace volmorph
