#include "Correspondence.h"

#include <string>

namespace volmorph::detail {
namespace {

std::string shape(const Mesh& mesh)
{
    return mesh.file.string() + " (" + std::to_string(mesh.points.size()) + " vertices, " +
           std::to_string(mesh.triangles.size()) + " triangles)";
}

void requireManifold(const Mesh& mesh, const SourceLocation& where)
{
    if (mesh.report.nonManifoldEdges > 0)
        throw UserError(where, mesh.file.string() + ": " +
                                   std::to_string(mesh.report.nonManifoldEdges) +
                                   " non-manifold edges (used by three or more triangles); a "
                                   "surface morph needs a manifold mesh");
}

} // namespace

std::string identityMismatch(const Mesh& source, const Mesh& target)
{
    if (source.points.size() != target.points.size() ||
        source.triangles.size() != target.triangles.size())
        return "the meshes differ in size: " + shape(source) + ", " + shape(target);
    for (size_t i = 0; i < source.triangles.size(); ++i)
        if (source.triangles[i] != target.triangles[i])
            return "the meshes differ in connectivity from triangle " + std::to_string(i) +
                   " on: " + shape(source) + ", " + shape(target);
    return {};
}

Corresponded correspond(Mesh source, Mesh target, const SurfaceSpec& spec)
{
    const SourceLocation& where =
        spec.correspondenceWhere.file.empty() ? spec.where : spec.correspondenceWhere;
    requireManifold(source, where);
    requireManifold(target, where);
    if (spec.correspondence != Correspondence::Auto &&
        spec.correspondence != Correspondence::Identity)
        throw UserError(where, std::string("surface.correspondence = \"") +
                                   name(spec.correspondence) +
                                   "\" is not in this version of volmorph; \"identity\" is (the "
                                   "same vertices and triangles on both sides)");
    if (const std::string why = identityMismatch(source, target); !why.empty())
        throw UserError(where, std::string("surface.correspondence = \"") +
                                   name(spec.correspondence) + "\": " + why +
                                   (spec.correspondence == Correspondence::Auto
                                        ? "; the identity is the only correspondence in this "
                                          "version (it needs the same vertices and triangles)"
                                        : "; the identity needs the same vertices and triangles"));
    return {std::move(source), std::move(target), Correspondence::Identity};
}

} // namespace volmorph::detail
