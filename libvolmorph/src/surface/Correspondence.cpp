#include "Correspondence.h"

#include "DiskMerge.h"
#include "SphereMerge.h"
#include "StarMerge.h"

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

std::vector<Vec3f> colorsOf(const Mesh& mesh, const Mesh& other)
{
    if (mesh.hasColors() || !other.hasColors()) return mesh.colors;
    return std::vector<Vec3f>(mesh.points.size(), Vec3f(0.8f)); // Voxelize.cpp's grey
}

Corresponded identity(const Mesh& source, const Mesh& target)
{
    Corresponded c;
    c.source.assign(source.points.begin(), source.points.end());
    c.target.assign(target.points.begin(), target.points.end());
    c.triangles = source.triangles;
    c.sourceColors = colorsOf(source, target);
    c.targetColors = colorsOf(target, source);
    if (source.hasUVs() || target.hasUVs())
        for (const auto& [mesh, uvs] :
             {std::pair{&source, &c.sourceUVs}, std::pair{&target, &c.targetUVs}}) {
            uvs->assign(3 * source.triangles.size(), Vec2d(0.0));
            if (mesh->hasUVs())
                for (size_t k = 0; k < uvs->size(); ++k) (*uvs)[k] = Vec2d(mesh->uvs[k]);
        }
    c.used = Correspondence::Identity;
    return c;
}

[[noreturn]] void refuse(const SurfaceSpec& spec, const SourceLocation& where,
                         const std::string& why)
{
    throw UserError(where, std::string("surface.correspondence = \"") + name(spec.correspondence) +
                               "\": " + why);
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

std::string starMismatch(const Mesh& mesh)
{
    const MeshReport& r = mesh.report;
    if (r.boundaryEdges > 0)
        return mesh.file.string() + " is not closed (" + std::to_string(r.boundaryEdges) +
               " boundary edges)";
    if (r.components != 1)
        return mesh.file.string() + " has " + std::to_string(r.components) + " pieces";
    // Euler: V - E + F = 2 - 2 genus, with E = 3F / 2 on a closed manifold.
    std::vector<char> used(mesh.points.size(), 0);
    for (const Vec3I& t : mesh.triangles) used[t[0]] = used[t[1]] = used[t[2]] = 1;
    long vertices = 0;
    for (char u : used) vertices += u;
    const long chi = vertices - long(mesh.triangles.size()) / 2;
    if (chi != 2)
        return mesh.file.string() + " has genus " + std::to_string((2 - chi) / 2) +
               " (a sphere's is 0)";
    if (!r.consistentlyOriented())
        return mesh.file.string() + " is not consistently oriented (" +
               std::to_string(r.misorientedEdges) + " edges)";
    return {};
}

namespace {

/// The message of a UserError with one diagnostic thrown at the correspondence's key `where` (""
/// for anything else: a kernel's own error, a landmark's, several diagnostics).
std::string reason(const UserError& e, const SourceLocation& where)
{
    const Diagnostic& d = e.diagnostics().front();
    const bool here =
        d.where.file == where.file && d.where.line == where.line && d.where.column == where.column;
    return e.diagnostics().size() == 1 && here && d.message.rfind("surface.kernel", 0) != 0
               ? d.message
               : std::string();
}

/// Why the disk merge does not apply before trying it: a closed mesh.
std::string diskMismatch(const Mesh& mesh)
{
    return mesh.report.boundaryEdges == 0 ? mesh.file.string() + " has no boundary (a closed mesh)"
                                          : std::string();
}

} // namespace

Corresponded correspond(const Mesh& source, const Mesh& target, const SurfaceSpec& spec,
                        Interrupter* interrupter)
{
    const SourceLocation& where =
        spec.correspondenceWhere.file.empty() ? spec.where : spec.correspondenceWhere;
    requireManifold(source, where);
    requireManifold(target, where);
    const Correspondence c = spec.correspondence;
    const bool automatic = c == Correspondence::Auto;
    const std::string notIdentity = identityMismatch(source, target);
    if (c == Correspondence::Identity) {
        if (!notIdentity.empty())
            refuse(spec, where,
                   notIdentity + "; the identity needs the same vertices and triangles");
        return identity(source, target);
    }
    if (automatic && notIdentity.empty()) return identity(source, target);
    // Kent's merge, then the disk merge: each its refusal, or (auto) all of them.
    std::string why = automatic ? notIdentity : std::string();
    auto fail = [&](const std::string& more) { why += (why.empty() ? "" : "; and ") + more; };
    if (c == Correspondence::Star || automatic) {
        std::string notStar = starMismatch(source);
        if (notStar.empty()) notStar = starMismatch(target);
        if (notStar.empty()) {
            try {
                return starMerge(source, target, spec.kernel, spec.landmarks, where);
            } catch (const UserError& e) {
                if (reason(e, where).empty()) throw;
                fail(reason(e, where));
            }
        } else {
            fail(notStar + "; Kent's star-shaped merge needs closed meshes of genus 0");
        }
    }
    if (c == Correspondence::Sphere || automatic) {
        throwIfInterrupted(interrupter);
        std::string notGenus0 = starMismatch(source);
        if (notGenus0.empty()) notGenus0 = starMismatch(target);
        if (notGenus0.empty())
            return sphereMerge(source, target, spec.landmarks, where, interrupter);
        if (!automatic || why.find(notGenus0) == std::string::npos)
            fail(notGenus0 + "; the spherical map needs closed meshes of genus 0");
    }
    if (c == Correspondence::Disk || automatic) {
        throwIfInterrupted(interrupter);
        std::string notDisk = diskMismatch(source);
        if (notDisk.empty()) notDisk = diskMismatch(target);
        if (notDisk.empty()) {
            try {
                return diskMerge(source, target, spec.landmarks, where);
            } catch (const UserError& e) {
                if (reason(e, where).empty()) throw;
                fail(reason(e, where));
            }
        } else {
            fail(notDisk + "; the disk map needs one boundary loop");
        }
    }
    refuse(spec, where, why + " (sdf and variational modes morph any shapes)");
}

} // namespace volmorph::detail
