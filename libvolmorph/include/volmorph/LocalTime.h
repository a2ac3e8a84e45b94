// The timing stage: the delay field d(x) of a scene's [timing] and the local time tau(x, t) it
// gives (TimingSettings.h), with their exact derivatives for the velocity's chain rule:
//   d tau / d t = 1 / (1 - spread) and grad tau = -grad d / (1 - spread) where 0 < tau < 1, 0
//   elsewhere.
// The delay: 0 everywhere, or the sweep's spread * s(u), u = (x - origin) . direction / length,
// s a ramp from 0 at u = 0 to 1 at u = 1, linear but over its first and last tenth, where it is
// quadratic (C1); then each region in order overrides it inside itself: d = (1 - w) d + w start,
// w = 1 inside the region's surface and falling to 0 at `softness` world units outside it
// (smoothstep of the signed distance, read through the quadratic B-spline of the level set's
// voxels: C1, its gradient exact; softness 0 is a hard edge, with no derivative there).
#pragma once

#include <volmorph/TimingSettings.h>
#include <volmorph/core/Math.h>

#include <openvdb/openvdb.h>

#include <optional>
#include <vector>

namespace volmorph {

/// A region of the delay field: its signed distance (world units, negative inside; valid to at
/// least `softness` outside its surface), its delay inside, and how far outside it fades.
struct TimingRegion {
    openvdb::FloatGrid::ConstPtr sdf;
    double start = 0.0;    ///< its delay, in t, in [0, spread]
    double softness = 0.0; ///< world units, >= 0
};

/// The delay and its gradient at one place.
struct Delay {
    double d = 0.0;      ///< in t, in [0, spread]
    Vec3d gradient{0.0}; ///< per world unit
};

/// The local time and its derivatives at one place and time.
struct LocalTau {
    double tau = 0.0;
    double dt = 1.0;     ///< d tau / d t
    Vec3d gradient{0.0}; ///< grad tau, per world unit
};

class LocalTime {
public:
    /// Everywhere at once: tau = t.
    LocalTime() = default;
    /// Throws std::invalid_argument for a spread outside [0, 1), a region without an sdf or with
    /// a start outside [0, spread].
    LocalTime(const TimingSettings& settings, std::vector<TimingRegion> regions);

    /// False when tau = t everywhere (no spread, no region).
    bool active() const { return mSpread > 0.0; }
    double spread() const { return mSpread; }

    /// The delay at world point x.
    Delay delay(const Vec3d& x) const;
    /// tau(x, t) and its derivatives at world point x.
    LocalTau at(const Vec3d& x, double t) const;
    /// The local time from a known delay.
    LocalTau fromDelay(const Delay& delay, double t) const;
    /// The largest |grad d| anywhere (per world unit): a bound for Lipschitz arguments.
    double maxDelayGradient() const;
    /// True when tau(., t) is clamped (0: not begun, or 1: done) everywhere within `radius` world
    /// units of x, by the delay at x and maxDelayGradient(); its value into `tau`.
    bool clampedWithin(const Vec3d& x, double radius, double t, double& tau) const;

private:
    double mSpread = 0.0;
    std::optional<TimingSweep> mSweep;
    std::vector<TimingRegion> mRegions;
};

} // namespace volmorph
