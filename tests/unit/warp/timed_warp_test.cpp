// The warp under a timing (warp/TimedWarp.h): its table's leaves against the exact warp at each
// voxel's own local time, a place that has not begun against the warp at 0 bit for bit, and the
// velocity against central differences of the map itself, in space and in t, with a sweep and
// with a region, both for the table and for the exact warp at tau; its domain test keeps every leaf
// whose points reach a side.
#include "support/WarpFixtures.h"

#include "warp/TimedWarp.h"
#include "warp/adaptive/DomainTest.h"

#include <volmorph/LocalTime.h>

#include <openvdb/math/Mat3.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <mutex>
#include <random>

using namespace volmorph;
using namespace volmorph::test;
using detail::TauTable;
using detail::TimedWarp;

namespace {

constexpr double kExtent = 48.0; ///< the pairs' cube, index units (voxel size 1: world = index)

/// Along y over the pairs' cube, spread 0.5.
LocalTime sweep(std::vector<TimingRegion> regions = {})
{
    TimingSettings s;
    s.spread = 0.5;
    s.sweep = TimingSweep{Vec3d(0.0, 4.0, 0.0), Vec3d(0.0, 1.0, 0.0), 40.0, {}};
    return LocalTime(s, std::move(regions));
}

/// A ball of radius 12 about (30, 20, 24) that starts at once, softness 6.
TimingRegion ball()
{
    return TimingRegion{openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
                            12.0f, openvdb::Vec3f(30.0f, 20.0f, 24.0f), 1.0f, 10.0f),
                        0.0, 6.0};
}

struct Warps {
    std::vector<FeaturePairSpec> pairs;
    WarpSpec spec;
    openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(1.0);
    TauTable table;
    explicit Warps(unsigned seed, int count = 4)
    {
        std::mt19937 random(seed);
        pairs = randomPairs(random, count, kExtent);
        spec.epsilon = 2.0;
        table = TauTable::make(pairs, spec, 1.0,
                               openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(47)), 0.25);
    }
    TimedWarp at(const LocalTime& time, double t, double tolerance) const
    {
        return TimedWarp(pairs, spec, 1.0, table, time, *xform, t, tolerance);
    }
};

/// Every leaf of `box` (default [0, 47]^3) from forEachLeaf, by origin; with `source`, those its
/// domain test keeps.
std::map<openvdb::Coord, detail::WarpLeaf>
leaves(const TimedWarp& warp,
       const openvdb::CoordBBox& box = openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(47)),
       const detail::Occupancy* source = nullptr)
{
    std::map<openvdb::Coord, detail::WarpLeaf> out;
    std::mutex m;
    warp.forEachLeaf(
        box, source, nullptr,
        [&](const detail::WarpLeaf& leaf) {
            std::lock_guard<std::mutex> lock(m);
            out[leaf.origin] = leaf;
        },
        nullptr, nullptr);
    return out;
}

/// v = -J^-1 dW/dt of one side from central differences of the map: in space (step 1e-3) and in
/// t (the frames at t +/- 1e-4). `withoutGradient`: the same with J less the chain rule's
/// (dW/dtau) (grad tau)^T, what a velocity that forgot tau's gradient would be.
Vec3d differencedVelocity(const Warps& s, const LocalTime& time, double t, double tolerance,
                          const Vec3d& p, int side, bool withoutGradient = false)
{
    auto mapped = [&](const TimedWarp& w, const Vec3d& x) {
        Vec3d a, b;
        w.map(x, a, b);
        return side == 0 ? a : b;
    };
    const TimedWarp now = s.at(time, t, tolerance);
    constexpr double h = 1e-3, dt = 1e-4;
    openvdb::math::Mat3d j;
    for (int k = 0; k < 3; ++k) {
        Vec3d step(0.0);
        step[k] = h;
        const Vec3d column = (mapped(now, p + step) - mapped(now, p - step)) / (2.0 * h);
        for (int i = 0; i < 3; ++i) j(i, k) = column[i];
    }
    const Vec3d rate =
        (mapped(s.at(time, t + dt, tolerance), p) - mapped(s.at(time, t - dt, tolerance), p)) /
        (2.0 * dt);
    if (withoutGradient) {
        const LocalTau local = now.tauAt(p); // dW/dtau = rate / tau_t
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) j(i, k) -= rate[i] / local.dt * local.gradient[k];
    }
    return -(j.inverse() * rate);
}

} // namespace

TEST(TimedWarp, ItsLeavesAreWithinItsBoundOfTheExactWarpAtEachVoxelsTime)
{
    // Each level's approximation keeps three quarters of the tolerance; the table adds its own
    // measured error (largest where an element's edge sweeps over a place: the weights have a
    // kink there in tau).
    const Warps s(7);
    EXPECT_GT(s.table.levels.size(), 17u); // halved where the warp bends
    const LocalTime time = sweep();
    for (const double t : {0.3, 0.6}) {
        const auto table = leaves(s.at(time, t, 0.25)), exact = leaves(s.at(time, t, 0.0));
        ASSERT_EQ(table.size(), 216u);
        ASSERT_EQ(exact.size(), 216u);
        double worst = 0.0;
        for (const auto& [origin, leaf] : table) {
            const detail::WarpLeaf& e = exact.at(origin);
            for (int n = 0; n < 512; ++n)
                worst = std::max({worst, double((leaf.source(n) - e.source(n)).length()),
                                  double((leaf.target(n) - e.target(n)).length())});
        }
        EXPECT_LT(worst, 0.75 * 0.25 + s.table.error) << "t " << t;
        EXPECT_GT(worst, 0.0) << "t " << t; // the table is not the exact warp
    }
}

TEST(TimedWarp, APlaceNotBegunIsTheWarpAtZeroBitForBit)
{
    // At t = 0.05 only the places below y = 10 have begun (their delay is under t): the leaves
    // from y = 16 up are all at tau 0, and hold the level-0 approximated warp's own points.
    const Warps s(11);
    const LocalTime time = sweep();
    const auto timed = leaves(s.at(time, 0.05, 0.25));
    const InverseWarp zero(s.pairs, s.spec, 0.0, 1.0);
    const detail::AdaptiveWarp plain(zero, 0.75 * 0.25);
    std::atomic<size_t> compared{0};
    plain.forEachLeaf(openvdb::CoordBBox(openvdb::Coord(0, 16, 0), openvdb::Coord(47)), nullptr,
                      nullptr, [&](const detail::WarpLeaf& leaf) {
                          const detail::WarpLeaf& other = timed.at(leaf.origin);
                          EXPECT_EQ(std::memcmp(leaf.s, other.s, sizeof leaf.s), 0);
                          EXPECT_EQ(std::memcmp(leaf.t, other.t, sizeof leaf.t), 0);
                          ++compared;
                      });
    EXPECT_GT(compared, 0u);
}

TEST(TimedWarp, ItsDomainTestKeepsEveryLeafWhosePointsReachASide)
{
    // A source occupied in one block-aligned cube; over a box three times the pairs' cube, the
    // leaves kept are a few of all, and every leaf with a voxel whose source point comes within a
    // sampler's reach of an occupied block is among them.
    const Warps s(5);
    const LocalTime time = sweep();
    openvdb::FloatGrid::Ptr occupied = openvdb::FloatGrid::create(0.0f);
    occupied->fill(openvdb::CoordBBox(openvdb::Coord(16), openvdb::Coord(31)), 1.0f, true);
    const detail::Occupancy source(occupied->tree());
    const openvdb::CoordBBox box(openvdb::Coord(-48), openvdb::Coord(95));
    for (const double t : {0.2, 0.5, 0.8}) {
        const TimedWarp warp = s.at(time, t, 0.25);
        const auto all = leaves(warp, box), kept = leaves(warp, box, &source);
        size_t reaching = 0;
        for (const auto& [origin, leaf] : all) {
            bool reaches = false;
            for (int n = 0; n < 512 && !reaches; ++n)
                reaches = detail::touches(&source, Vec3d(leaf.source(n)), Vec3d(leaf.source(n)),
                                          detail::kSamplerReach);
            if (!reaches) continue;
            ++reaching;
            EXPECT_TRUE(kept.count(origin)) << "t " << t << " leaf " << origin;
        }
        EXPECT_GT(reaching, 0u) << "t " << t;
        EXPECT_LT(kept.size(), all.size() / 4) << "t " << t;
    }
}

TEST(TimedWarp, TheVelocityIsTheMapsOwnDerivativeUnderASweepAndARegion)
{
    const Warps s(3);
    const std::pair<const char*, LocalTime> timings[] = {{"sweep", sweep()},
                                                         {"region", sweep({ball()})}};
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(4.0, 44.0);
    for (const auto& [name, time] : timings)
        for (const double tolerance : {0.25, 0.0}) {
            const double t = 0.45;
            const TimedWarp warp = s.at(time, t, tolerance);
            int checked = 0;
            double without = 0.0; // the mean relative error without tau's gradient
            for (int i = 0; i < 400 && checked < 60; ++i) {
                const Vec3d p(u(random), u(random), u(random));
                // Strictly inside the ramp, and (for the table) within one interval meanwhile.
                const double before = s.at(time, t - 1e-4, 0.0).tauAt(p).tau;
                const double after = s.at(time, t + 1e-4, 0.0).tauAt(p).tau;
                if (!(before > 0.0 && after < 1.0)) continue;
                double f0, f1;
                if (s.table.interval(before, f0) != s.table.interval(after, f1)) continue;
                Vec3d v[2];
                bool regular;
                warp.velocities().velocities(&p, 1, &v[0], &v[1], &regular);
                if (!regular) continue;
                for (int side = 0; side < 2; ++side) {
                    const Vec3d fd = differencedVelocity(s, time, t, tolerance, p, side);
                    EXPECT_LT((v[side] - fd).length(), 0.01 * fd.length() + 1e-6)
                        << name << " tolerance " << tolerance << " at " << p << " side " << side;
                    const Vec3d forgot = differencedVelocity(s, time, t, tolerance, p, side, true);
                    without += (forgot - fd).length() / fd.length();
                }
                ++checked;
            }
            EXPECT_GE(checked, 40) << name;
            // The chain rule's term matters: without it the velocity is off by far more.
            EXPECT_GT(without / (2 * checked), 0.05) << name;
        }
}
