// Issue 40's solver speed: the two-level partition of unity against Eigen's dense LU of the same
// constraints, side by side in one run. The dense solve is timed where it fits (2000, 4000, 8000
// constraints) and extrapolated as N^3 from the largest; the partition of unity at the count asked
// (default 20,000). Two morphs of spheres (voxel 0.01): one into a concentric one twice its radius,
// one into two spheres. Prints a table for BENCHMARKS.md.
//
//   volmorph_bench_variational_solver [CONSTRAINTS]
#include "blend/variational/Constraints.h"
#include "blend/variational/Interpolant.h"
#include "blend/variational/PartitionOfUnity.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Composite.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace volmorph::detail::variational;

namespace {

constexpr double kVoxel = 0.01, kTimeScale = 0.25;

double seconds()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

openvdb::FloatGrid::Ptr sphere(double radius, double x = 0.0)
{
    return openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
        float(radius), openvdb::Vec3f(float(x), 0.0f, 0.0f), float(kVoxel), 3.0f);
}

/// About `count` constraints, half on each shape (kConstraintsPerPoint per surface point).
std::vector<Constraint> constraints(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b,
                                    size_t count)
{
    const size_t points = count / (2 * kConstraintsPerPoint);
    std::vector<Constraint> c = sampleConstraints(a, points, kVoxel, 0.0);
    const std::vector<Constraint> d = sampleConstraints(b, points, kVoxel, kTimeScale);
    c.insert(c.end(), d.begin(), d.end());
    return c;
}

void row(const std::string& name, const openvdb::FloatGrid& a, const openvdb::FloatGrid& b,
         size_t count)
{
    double dense = 0.0;
    size_t largest = 0;
    for (size_t n : {2000, 4000, 8000}) {
        const std::vector<Constraint> c = constraints(a, b, n);
        const double start = seconds();
        Interpolant::solveDense(c);
        dense = seconds() - start;
        largest = c.size();
        std::printf("  %s: dense solve of %zu constraints %.2f s\n", name.c_str(), c.size(), dense);
    }
    const std::vector<Constraint> c = constraints(a, b, count);
    const double start = seconds();
    const PartitionOfUnity pu = PartitionOfUnity::solve(c);
    const double fast = seconds() - start;
    const double extrapolated = dense * std::pow(double(c.size()) / double(largest), 3.0);
    std::printf("| %s | %zu | %.2f | %zu | %.1f | %.0fx |\n", name.c_str(), c.size(), fast,
                pu.patchCount(), extrapolated, extrapolated / fast);
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    const size_t count = argc > 1 ? size_t(std::atol(argv[1])) : 20000;
    std::printf("| morph | constraints | partition of unity (s) | balls | dense LU, N^3 from the "
                "largest timed (s) | speed-up |\n|---|---:|---:|---:|---:|---:|\n");
    auto two = sphere(0.25, -0.35);
    openvdb::tools::csgUnion(*two, *sphere(0.25, 0.35));
    row("sphere 0.3 into 0.6", *sphere(0.3), *sphere(0.6), count);
    row("sphere into two spheres", *sphere(0.3), *two, count);
    return 0;
}
