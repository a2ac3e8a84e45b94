// Issue 57's spherical parameterization figures, not a test: for each closed genus-0 mesh given,
// the time of the map (Praun and Hoppe's progressive-mesh method, surface/SphereParam.h), its L2
// stretch efficiency, the triangles turned over by the exact predicate and the total spherical
// area against 4 pi.
//
// usage: volmorph_bench_sphere_param MESH...
#include "surface/MergeSide.h"
#include "surface/SphereParam.h"
#include "surface/SpherePredicates.h"
#include "surface/SphereStretch.h"

#include <volmorph/Mesh.h>

#include <chrono>
#include <cmath>
#include <cstdio>

int main(int argc, char** argv)
{
    using namespace volmorph;
    using namespace volmorph::detail;
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s MESH...\n", argv[0]);
        return 2;
    }
    for (int i = 1; i < argc; ++i) {
        try {
            const Mesh mesh = importMesh(argv[i]);
            const MergeSide side(mesh);
            const auto start = std::chrono::steady_clock::now();
            const SphereMap map = sphericalMap(side.points, side.triangles);
            const double seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            size_t turned = 0;
            double area = 0.0;
            for (const Vec3I& t : side.triangles) {
                const Vec3d &p = map.directions[t[0]], &q = map.directions[t[1]],
                            &r = map.directions[t[2]];
                turned += orientation(toGrid(p), toGrid(q), toGrid(r)) <= 0;
                area += sphericalArea(p, q, r);
            }
            std::printf("%s: %zu triangles, %.2f s, stretch efficiency %.3f, %zu turned over, "
                        "area - 4 pi = %.2e\n",
                        argv[i], side.triangles.size(), seconds, map.stretchEfficiency, turned,
                        area - 4.0 * M_PI);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s: %s\n", argv[i], e.what());
        }
    }
    return 0;
}
