// Issue 57's self-intersection count, not a test: the number of pairs of triangles of a mesh that
// intersect (sharing no vertex), for each mesh file given (a surface morph's PLY frames).
//
// Each edge is traced as a segment through the mesh with Embree, every hit kept by a filter; a
// hit on a triangle that does not share a vertex with the edge, with the edge's ends on opposite
// sides of its plane (by more than float rounding), means that triangle and both triangles of the
// edge intersect. Two triangles in general position intersect exactly when an
// edge of one crosses the other, so every intersecting pair is found (pairs that share a vertex
// and also cross elsewhere are not counted).
//
// usage: volmorph_bench_self_intersections MESH...
#include <volmorph/Mesh.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <unordered_map>
#include <vector>

namespace {

using namespace volmorph;

struct Hits {
    RTCIntersectContext context; // first: Embree passes this pointer to the filter
    std::vector<unsigned> triangles;
};

void keepEveryHit(const RTCFilterFunctionNArguments* args)
{
    auto* hits = reinterpret_cast<Hits*>(args->context);
    hits->triangles.push_back(RTCHitN_primID(args->hit, args->N, 0));
    args->valid[0] = 0; // reject: the trace goes on to the next hit
}

/// The edge (a, b) has its ends on opposite sides of triangle u's plane, each by more than 1e-5 of
/// the edge's length plus the points' float rounding (`rounding`, world units): a crossing, not a
/// graze of a coplanar neighbour (a merged mesh's triangles within one input face are coplanar,
/// and its slivers are shorter than a float's step).
bool transversal(const Mesh& mesh, const Vec3I& u, uint32_t a, uint32_t b, double rounding)
{
    const Vec3d p0(mesh.points[u[0]]);
    const Vec3d n = (Vec3d(mesh.points[u[1]]) - p0).cross(Vec3d(mesh.points[u[2]]) - p0).unitSafe();
    const Vec3d pa(mesh.points[a]), pb(mesh.points[b]);
    const double da = n.dot(pa - p0), db = n.dot(pb - p0),
                 tol = 1e-5 * (pb - pa).length() + rounding;
    return (da > tol && db < -tol) || (da < -tol && db > tol);
}

size_t intersectingPairs(const Mesh& mesh)
{
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.points.size()));
    for (size_t i = 0; i < mesh.points.size(); ++i)
        for (int c = 0; c < 3; ++c) v[3 * i + c] = mesh.points[i][c];
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0,
                                                             RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
                                                             mesh.triangles.size()));
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
        for (int c = 0; c < 3; ++c) t[3 * i + c] = mesh.triangles[i][c];
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);

    std::unordered_map<uint64_t, std::vector<unsigned>> edges; // edge -> its triangles
    for (unsigned i = 0; i < mesh.triangles.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const uint32_t a = mesh.triangles[i][c], b = mesh.triangles[i][(c + 1) % 3];
            edges[uint64_t(std::min(a, b)) << 32 | std::max(a, b)].push_back(i);
        }
    const auto [lo, hi] = mesh.bounds();
    const double rounding = 8.0 * std::numeric_limits<float>::epsilon() *
                            std::max({std::abs(lo.x()), std::abs(lo.y()), std::abs(lo.z()),
                                      std::abs(hi.x()), std::abs(hi.y()), std::abs(hi.z())});
    std::set<std::pair<unsigned, unsigned>> pairs;
    for (const auto& [key, sides] : edges) {
        const uint32_t a = uint32_t(key >> 32), b = uint32_t(key);
        Hits hits;
        rtcInitIntersectContext(&hits.context);
        hits.context.filter = keepEveryHit;
        RTCRayHit rh{};
        const Vec3f o = mesh.points[a], d = mesh.points[b] - mesh.points[a];
        rh.ray.org_x = o.x(), rh.ray.org_y = o.y(), rh.ray.org_z = o.z();
        rh.ray.dir_x = d.x(), rh.ray.dir_y = d.y(), rh.ray.dir_z = d.z();
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = 1.0f;
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &hits.context, &rh);
        for (unsigned other : hits.triangles) {
            const Vec3I& u = mesh.triangles[other];
            if (u[0] == a || u[1] == a || u[2] == a || u[0] == b || u[1] == b || u[2] == b)
                continue;
            if (!transversal(mesh, u, a, b, rounding)) continue;
            for (unsigned side : sides) {
                const Vec3I& s = mesh.triangles[side];
                bool shares = false;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) shares |= s[i] == u[j];
                if (!shares) pairs.emplace(std::min(side, other), std::max(side, other));
            }
        }
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return pairs.size();
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s MESH...\n", argv[0]);
        return 2;
    }
    for (int i = 1; i < argc; ++i) {
        try {
            const Mesh m = importMesh(argv[i]);
            std::printf("%s: %zu triangles, %zu intersecting pairs\n", argv[i], m.triangles.size(),
                        intersectingPairs(m));
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
    }
    return 0;
}
