// The warp's stretch (warp/Stretch.h) against OpenVDB's own diagonalization.
#include "support/WarpFixtures.h"

using namespace volmorph;
using namespace volmorph::test;

TEST(Stretch, SpectralNormMatchesOpenVdbsDiagonalization)
{
    // The closed form against OpenVDB's Jacobi iteration, on random Jacobians and on the
    // degenerate ones (repeated eigenvalues, rank 1 and 0, diagonal).
    std::mt19937 random(5);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::vector<std::array<Vec3d, 3>> cases = {
        {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)},
        {Vec3d(2, 0, 0), Vec3d(0, 3, 0), Vec3d(0, 0, 0.5)},
        {Vec3d(1, 2, 3), Vec3d(2, 4, 6), Vec3d(-1, -2, -3)},
        {Vec3d(0.0), Vec3d(0.0), Vec3d(0.0)},
        {Vec3d(0, 1, 0), Vec3d(-1, 0, 0), Vec3d(0, 0, 1)},
        {Vec3d(1, 1e-9, 0), Vec3d(0, 1, 1e-9), Vec3d(1e-9, 0, 1)},
    };
    for (int i = 0; i < 1000; ++i)
        cases.push_back({Vec3d(u(random), u(random), u(random)),
                         Vec3d(u(random), u(random), u(random)),
                         Vec3d(u(random), u(random), u(random))});
    for (const auto& [dx, dy, dz] : cases) {
        const openvdb::math::Mat3d j(dx.x(), dy.x(), dz.x(), dx.y(), dy.y(), dz.y(), dx.z(), dy.z(),
                                     dz.z());
        openvdb::math::Mat3d q;
        Vec3d eigen;
        ASSERT_TRUE(openvdb::math::diagonalizeSymmetricMatrix(j.transpose() * j, q, eigen));
        const double expected = std::sqrt(std::max({eigen.x(), eigen.y(), eigen.z(), 0.0}));
        EXPECT_NEAR(detail::spectralNorm(dx, dy, dz), expected, 1e-7 * std::max(1.0, expected))
            << dx << dy << dz;
    }
}
