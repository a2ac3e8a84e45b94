#include <volmorph/Export.h>

#include <volmorph/core/AtomicFile.h>

#include <assimp/Exporter.hpp>
#include <assimp/scene.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <memory>
#include <stdexcept>

namespace volmorph {

Mesh surfaceMesh(const VolumeSet& volumes, double adaptivity)
{
    const bool fromSdf = bool(volumes.sdf);
    const openvdb::FloatGrid& grid = fromSdf ? *volumes.sdf : *volumes.density;
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(grid, points, triangles, quads, fromSdf ? 0.0 : 0.5, adaptivity);
    Mesh mesh;
    mesh.points.assign(points.begin(), points.end());
    mesh.triangles.assign(triangles.begin(), triangles.end());
    for (const openvdb::Vec4I& q : quads) {
        mesh.triangles.emplace_back(q[0], q[1], q[2]);
        mesh.triangles.emplace_back(q[0], q[2], q[3]);
    }
    // Outward: a closed surface's signed volume is positive. (A fog's 0.5 isosurface winds the
    // other way from a level set's zero set, so check rather than assume.)
    double volume = 0.0;
    for (const Vec3I& t : mesh.triangles)
        volume +=
            Vec3d(mesh.points[t[0]]).dot(Vec3d(mesh.points[t[1]]).cross(Vec3d(mesh.points[t[2]])));
    if (volume < 0.0)
        for (Vec3I& t : mesh.triangles) std::swap(t[1], t[2]);
    if (volumes.color) {
        auto acc = volumes.color->getConstAccessor();
        mesh.colors.reserve(mesh.points.size());
        for (const Vec3f& p : mesh.points)
            mesh.colors.push_back(
                openvdb::tools::BoxSampler::sample(acc, volumes.color->worldToIndex(Vec3d(p))));
    }
    mesh.report.inputTriangles = mesh.triangles.size();
    analyzeTopology(mesh);
    return mesh;
}

void writeMesh(const Mesh& mesh, const std::filesystem::path& path)
{
    const std::string ext = path.extension().string();
    // ASCII PLY: Assimp 5.2's binary PLY output does not read back through its own importer (face
    // indices out of range; measured). OBJ without a .mtl: a material file would be named after the
    // temporary file, and volmorph writes no materials.
    const char* format = ext == ".ply" ? "ply" : ext == ".obj" ? "objnomtl" : nullptr;
    if (!format)
        throw UserError(SourceLocation{path.string()},
                        "expected a mesh file name ending in .ply or .obj");

    // Assimp's scene owns its arrays and frees them with delete[].
    auto scene = std::make_unique<aiScene>();
    scene->mRootNode = new aiNode();
    scene->mRootNode->mNumMeshes = 1;
    scene->mRootNode->mMeshes = new unsigned[1]{0};
    scene->mNumMaterials = 1;
    scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
    scene->mNumMeshes = 1;
    scene->mMeshes = new aiMesh* [1] { new aiMesh() };
    aiMesh& m = *scene->mMeshes[0];
    m.mMaterialIndex = 0;
    m.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    m.mNumVertices = unsigned(mesh.points.size());
    m.mVertices = new aiVector3D[m.mNumVertices];
    for (unsigned i = 0; i < m.mNumVertices; ++i)
        m.mVertices[i] = aiVector3D(mesh.points[i].x(), mesh.points[i].y(), mesh.points[i].z());
    if (mesh.hasColors()) {
        m.mColors[0] = new aiColor4D[m.mNumVertices];
        for (unsigned i = 0; i < m.mNumVertices; ++i)
            m.mColors[0][i] =
                aiColor4D(mesh.colors[i].x(), mesh.colors[i].y(), mesh.colors[i].z(), 1.0f);
    }
    m.mNumFaces = unsigned(mesh.triangles.size());
    m.mFaces = new aiFace[m.mNumFaces];
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
        m.mFaces[f].mNumIndices = 3;
        m.mFaces[f].mIndices =
            new unsigned[3]{mesh.triangles[f][0], mesh.triangles[f][1], mesh.triangles[f][2]};
    }

    writeAtomically(path, "mesh", [&](const std::filesystem::path& temporary) {
        Assimp::Exporter exporter;
        if (exporter.Export(scene.get(), format, temporary.string()) != aiReturn_SUCCESS)
            throw std::runtime_error(exporter.GetErrorString());
    });
}

} // namespace volmorph
