// Surface morphs under a timing (issue 59): a tube bending by 120 degrees, swept along its length
// so that the bend starts at one end. Each vertex is at the local time of its own place (the point
// of its straight path where the place's tau is the vertex's own), the places the sweep has passed
// are the target's and those it has not reached the source's; the velocity, straight line and
// as-rigid-as-possible, is the positions' derivative in t (central differences), the chain rule
// through the place's time included; a scene in surface mode takes [timing].
#include <volmorph/LocalTime.h>
#include <volmorph/Scene.h>
#include <volmorph/SceneSurface.h>
#include <volmorph/SurfaceMorph.h>

#include "support/SurfaceShapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace volmorph {
namespace {

using test::bent;
using test::tube;

constexpr double kLength = 4.0, kRadius = 0.3, kBend = 2.0 * M_PI / 3.0;

/// Along x from a quarter of the tube's length, over half of it, spread 0.5: half way, the first
/// quarter is done and the last quarter has not begun.
LocalTime alongTheTube()
{
    TimingSettings s;
    s.spread = 0.5;
    s.sweep = TimingSweep{Vec3d(0.25 * kLength, 0.0, 0.0), Vec3d(1.0, 0.0, 0.0), 0.5 * kLength, {}};
    return LocalTime(s, {});
}

PlaceTime placeTime(const LocalTime& time, double t)
{
    return [&time, t](const Vec3d& x) {
        const LocalTau l = time.at(x, t);
        return PlaceTau{l.tau, l.dt, l.gradient};
    };
}

SurfaceSpec spec(SurfaceInterpolation interpolation)
{
    SurfaceSpec s;
    s.correspondence = Correspondence::Identity;
    s.interpolation = interpolation;
    return s;
}

TEST(SurfaceTiming, EachVertexIsAtItsOwnPlacesTime)
{
    const Mesh a = tube(41, 16, kLength, kRadius), b = bent(a, kLength, kBend);
    const SurfaceMorpher line(a, b, spec(SurfaceInterpolation::Linear));
    const LocalTime time = alongTheTube();
    const double t = 0.5;
    const SurfaceFrame f = line.frame(placeTime(time, t), placeTime(time, t));
    size_t done = 0, waiting = 0, underway = 0;
    double worst = 0.0;
    for (size_t i = 0; i < f.points.size(); ++i) {
        const Vec3d from(a.points[i]), path = Vec3d(b.points[i]) - from;
        if (path.length() < 1e-6) continue; // a vertex that does not move
        const double s = (f.points[i] - from).dot(path) / path.lengthSqr();
        EXPECT_LT((f.points[i] - (from + s * path)).length(), 1e-12); // on its straight line
        worst = std::max(worst, std::abs(s - time.at(f.points[i], t).tau));
        done += s == 1.0;
        waiting += s == 0.0;
        underway += s > 0.0 && s < 1.0;
        if (s == 1.0) {
            EXPECT_EQ(f.points[i], Vec3d(b.points[i]));
        }
        if (s == 0.0) {
            EXPECT_EQ(f.points[i], Vec3d(a.points[i]));
        }
    }
    std::printf("half way: %zu vertices done, %zu not begun, %zu under way; each at its place's "
                "time within %.1e\n",
                done, waiting, underway, worst);
    EXPECT_LT(worst, 1e-12);
    EXPECT_GT(done, 50u);
    EXPECT_GT(waiting, 50u);
    EXPECT_GT(underway, 50u);
}

TEST(SurfaceTiming, TheVelocityIsThePositionsDerivativeInT)
{
    const Mesh a = tube(41, 16, kLength, kRadius), b = bent(a, kLength, kBend);
    const LocalTime time = alongTheTube();
    const double h = 1e-5;
    for (const auto interpolation : {SurfaceInterpolation::Linear, SurfaceInterpolation::Arap}) {
        const SurfaceMorpher morpher(a, b, spec(interpolation));
        for (const double t : {0.3, 0.6}) {
            const SurfaceFrame f = morpher.frame(placeTime(time, t), placeTime(time, t));
            const SurfaceFrame lo = morpher.frame(placeTime(time, t - h), placeTime(time, t - h));
            const SurfaceFrame hi = morpher.frame(placeTime(time, t + h), placeTime(time, t + h));
            double worst = 0.0, fastest = 0.0;
            for (size_t i = 0; i < f.points.size(); ++i) {
                const Vec3d difference = (hi.points[i] - lo.points[i]) / (2.0 * h);
                worst = std::max(worst, (f.velocity[i] - difference).length());
                fastest = std::max(fastest, difference.length());
            }
            std::printf("%s, t %.1f: velocity against central differences within %.2e (fastest "
                        "vertex %.3f world units per unit t)\n",
                        name(interpolation), t, worst, fastest);
            EXPECT_GT(fastest, 0.1);
            EXPECT_LT(worst, 1e-3 * fastest) << name(interpolation) << " t " << t;
        }
    }
}

TEST(SurfaceTiming, ASurfaceSceneTakesATiming)
{
    // The surface-mode example with a sweep along x: the scene reads, and half way its in-between
    // differs from the one without the timing; the ends are the same.
    const std::filesystem::path root = VOLMORPH_SOURCE_DIR;
    std::ifstream in(root / "scenes" / "blobby-to-star-surface.toml");
    std::stringstream text;
    text << in.rdbuf();
    const std::string swept =
        text.str() + "\n[timing]\nspread = 0.5\n"
                     "sweep = { origin = [-0.6, 0, 0], direction = [1, 0, 0], length = 1.2 }\n";
    const Scene plainScene = parseScene(text.str(), root / "scenes" / "plain.toml");
    const Scene scene = parseScene(swept, root / "scenes" / "swept.toml");
    const SceneSurface plain(plainScene), timed(scene);
    ASSERT_NE(timed.localTime(), nullptr);
    const int first = scene.frames.first, last = scene.frames.last;
    const int middle = (first + last) / 2;
    const SurfaceFrame p = plain.frame(middle), s = timed.frame(middle);
    ASSERT_EQ(p.points.size(), s.points.size());
    double apart = 0.0;
    for (size_t i = 0; i < p.points.size(); ++i)
        apart = std::max(apart, (p.points[i] - s.points[i]).length());
    EXPECT_GT(apart, 0.01);
    for (const int f : {first, last}) {
        const SurfaceFrame a = plain.frame(f), b = timed.frame(f);
        for (size_t i = 0; i < a.points.size(); ++i)
            EXPECT_LT((a.points[i] - b.points[i]).length(), 1e-9) << "frame " << f;
    }
}

} // namespace
} // namespace volmorph
