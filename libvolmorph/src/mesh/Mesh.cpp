// Mesh import through Assimp, then clean-up and topology checks of our own.
//
// Assimp's JoinIdenticalVertices compares normals and texture coordinates too, so an STL file (one
// normal per face) would stay a soup of unconnected triangles. We weld on exact positions instead,
// which is what topology (holes, non-manifold edges, shells) is about.
#include <volmorph/Mesh.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace volmorph {
namespace {

struct PositionHash {
    size_t operator()(const Vec3f& p) const
    {
        // Positions are compared exactly; +0 and -0 are made equal by the caller.
        size_t h = 0;
        for (int i = 0; i < 3; ++i) {
            const float v = p[i];
            uint32_t bits;
            std::memcpy(&bits, &v, sizeof bits);
            h ^= std::hash<uint32_t>()(bits) + 0x9e3779b9 + (h << 6) + (h >> 2);
        }
        return h;
    }
};

SourceLocation errorPlace(const std::filesystem::path& file, const SourceLocation& where)
{
    return where.file.empty() ? SourceLocation{file.string()} : where;
}

std::string prefix(const std::filesystem::path& file, const SourceLocation& where)
{
    // When the error is reported at a scene key, the message still names the mesh file.
    return where.file.empty() ? std::string() : "mesh '" + file.string() + "': ";
}

/// Union-find over vertices, for counting connected shells.
struct DisjointSets {
    std::vector<uint32_t> parent;
    explicit DisjointSets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    uint32_t find(uint32_t x)
    {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

} // namespace

std::pair<Vec3d, Vec3d> Mesh::bounds() const
{
    const double inf = std::numeric_limits<double>::infinity();
    Vec3d lo(inf), hi(-inf);
    for (const Vec3f& p : points) {
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], double(p[i]));
            hi[i] = std::max(hi[i], double(p[i]));
        }
    }
    return {lo, hi};
}

void analyzeTopology(Mesh& mesh)
{
    MeshReport& r = mesh.report;
    // Each undirected edge (a < b) counts its uses and how many times it is traversed a -> b.
    // A consistently oriented manifold edge is used twice, once in each direction.
    struct EdgeUse {
        uint32_t count = 0;
        uint32_t forward = 0;
    };
    std::unordered_map<uint64_t, EdgeUse> edges;
    edges.reserve(mesh.triangles.size() * 2);
    DisjointSets sets(mesh.points.size());
    for (const Vec3I& tri : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = tri[k], b = tri[(k + 1) % 3];
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            EdgeUse& use = edges[key];
            ++use.count;
            if (a < b) ++use.forward;
            sets.unite(a, b);
        }
    }
    r.boundaryEdges = r.nonManifoldEdges = r.misorientedEdges = 0;
    for (const auto& [key, use] : edges) {
        if (use.count == 1) ++r.boundaryEdges;
        else if (use.count > 2) ++r.nonManifoldEdges;
        else if (use.forward != 1) ++r.misorientedEdges;
    }
    std::vector<char> used(mesh.points.size(), 0);
    for (const Vec3I& tri : mesh.triangles)
        for (int k = 0; k < 3; ++k) used[tri[k]] = 1;
    r.components = 0;
    for (uint32_t v = 0; v < mesh.points.size(); ++v)
        if (used[v] && sets.find(v) == v) ++r.components;
}

Mesh importMesh(const std::filesystem::path& file, const ObjectTransform& transform,
                const SourceLocation& where)
{
    const SourceLocation place = errorPlace(file, where);
    const std::string pre = prefix(file, where);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        throw UserError(place, pre + "mesh file not found or not a regular file");
    if (std::filesystem::file_size(file, ec) == 0)
        throw UserError(place, pre + "mesh file is empty");

    Assimp::Importer importer;
    // Points and lines are of no use to a voxelizer; let Assimp drop them.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_PreTransformVertices |
                           aiProcess_SortByPType | aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(file.string(), flags);
    if (!scene) {
        std::string why = importer.GetErrorString();
        if (why.empty()) why = "unknown reason";
        throw UserError(place, pre + "cannot read mesh (" + why + ")");
    }
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
        throw UserError(place, pre + "the mesh file is incomplete or malformed");

    Mesh mesh;
    mesh.file = file;
    const Mat4d m = transform.matrix();
    std::unordered_map<Vec3f, uint32_t, PositionHash> index;
    bool anyColors = false;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi)
        anyColors = anyColors || scene->mMeshes[mi]->HasVertexColors(0);

    std::vector<uint32_t> remap;
    for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
        const aiMesh* am = scene->mMeshes[mi];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        remap.assign(am->mNumVertices, 0);
        for (unsigned v = 0; v < am->mNumVertices; ++v) {
            const aiVector3D& a = am->mVertices[v];
            if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(a.z))
                throw UserError(place, pre + "vertex " + std::to_string(v + 1) +
                                           " has a non-finite coordinate (NaN or inf)");
            const Vec3d w = m.transform(Vec3d(a.x, a.y, a.z));
            Vec3f p(float(w.x()) + 0.0f, float(w.y()) + 0.0f, float(w.z()) + 0.0f); // -0 -> +0
            if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
                throw UserError(place, pre + "vertex " + std::to_string(v + 1) +
                                           " is out of range after the transform");
            const auto [it, inserted] = index.try_emplace(p, uint32_t(mesh.points.size()));
            if (inserted) {
                mesh.points.push_back(p);
                if (anyColors) {
                    Vec3f c(0.8f);
                    if (am->HasVertexColors(0)) {
                        const aiColor4D& ac = am->mColors[0][v];
                        c = Vec3f(ac.r, ac.g, ac.b);
                    }
                    mesh.colors.push_back(c);
                }
            } else {
                ++mesh.report.duplicateVertices;
            }
            remap[v] = it->second;
        }
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace& face = am->mFaces[f];
            if (face.mNumIndices != 3) continue;
            ++mesh.report.inputTriangles;
            const Vec3I tri(remap[face.mIndices[0]], remap[face.mIndices[1]], remap[face.mIndices[2]]);
            if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
                ++mesh.report.degenerateTriangles;
                continue;
            }
            const Vec3d a(mesh.points[tri[0]]), b(mesh.points[tri[1]]), c(mesh.points[tri[2]]);
            if ((b - a).cross(c - a).lengthSqr() == 0.0) {
                ++mesh.report.degenerateTriangles;
                continue;
            }
            mesh.triangles.push_back(tri);
        }
    }
    if (mesh.report.inputTriangles == 0)
        throw UserError(place, pre + "the mesh has no triangles");
    if (mesh.triangles.empty())
        throw UserError(place, pre + "every one of the mesh's " +
                                   std::to_string(mesh.report.inputTriangles) +
                                   " triangles is degenerate (zero area)");
    analyzeTopology(mesh);
    return mesh;
}

SceneMeshes importSceneMeshes(const Scene& scene)
{
    SceneMeshes out;
    std::vector<Diagnostic> problems;
    const std::pair<const ObjectSpec*, Mesh*> sides[2] = {{&scene.source, &out.source},
                                                          {&scene.target, &out.target}};
    for (const auto& [spec, mesh] : sides) {
        try {
            *mesh = importMesh(spec->mesh, spec->transform, spec->meshWhere);
        } catch (const UserError& e) {
            problems.insert(problems.end(), e.diagnostics().begin(), e.diagnostics().end());
        }
    }
    if (!problems.empty()) throw UserError(problems);
    return out;
}

} // namespace volmorph
