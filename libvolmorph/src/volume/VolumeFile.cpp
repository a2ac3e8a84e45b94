#include "volume/VolumeFile.h"

#include "volume/NiftiFile.h"

#include <volmorph/core/VdbRead.h>

#include <algorithm>
#include <limits>

namespace volmorph::detail {
namespace {

bool isFloat(const openvdb::GridBase& g)
{
    return g.isType<openvdb::FloatGrid>();
}

bool isVec3(const openvdb::GridBase& g)
{
    return g.isType<openvdb::Vec3SGrid>();
}

std::string joined(const std::vector<std::string>& names)
{
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? "no grids" : s;
}

} // namespace

openvdb::math::Transform::Ptr placedTransform(const openvdb::math::Transform& grid,
                                              const ObjectTransform& object)
{
    openvdb::math::Transform::Ptr xf = grid.copy();
    // OpenVDB's matrices act on row vectors: post-multiplying applies the object's placement
    // after the grid's own index-to-world map.
    if (!object.isIdentity()) xf->postMult(object.matrix());
    return xf;
}

VolumeFile::VolumeFile(const VolumeSource& source) : mSource(source)
{
    try {
        mGrids = isNiftiFile(source.file) ? readNiftiGrids(source.file, source.window)
                                          : readVdbGrids(source.file);
    } catch (const std::exception& e) {
        throw error(std::string("cannot read volume file (") + e.what() + ")");
    }
    VolumeFileInfo& i = mInfo;
    i.density = pick("density", source.grids.density, {"density"}, false);
    i.sdf = pick("sdf", source.grids.sdf, {"surface", "sdf"}, false);
    i.color = pick("color", source.grids.color, {"Cd", "color"}, true);
    std::vector<std::string> names;
    for (const auto& g : *mGrids) {
        const std::string& name = g->getName();
        names.push_back(name);
        if (name == i.density || name == i.sdf || name == i.color) continue;
        if (std::find(i.extras.begin(), i.extras.end(), name) != i.extras.end()) continue;
        (isFloat(*g) || isVec3(*g) ? i.extras : i.ignored).push_back(name);
    }
    if (i.density.empty() && i.sdf.empty())
        throw error("holds no density or level-set grid (it holds: " + joined(names) +
                    "); name one, e.g. grids = { density = \"NAME\" }");
    for (const auto& g : *mGrids)
        if (!g->transform().isLinear())
            throw error("grid '" + g->getName() +
                        "' has a frustum (non-linear) transform; resample it onto a linear "
                        "transform first (in Houdini: VDB Resample)");
    measure();
}

UserError VolumeFile::error(const std::string& what) const
{
    const SourceLocation at =
        mSource.where.file.empty() ? SourceLocation{mSource.file.string()} : mSource.where;
    return UserError(at, "volume '" + mSource.file.string() + "': " + what);
}

openvdb::GridBase::Ptr VolumeFile::grid(const std::string& name) const
{
    for (const auto& g : *mGrids)
        if (g->getName() == name) return g;
    return nullptr;
}

/// The grid that plays `part`: `given`, or the first default the file holds. Checks its type.
std::string VolumeFile::pick(const std::string& part, const std::string& given,
                             std::initializer_list<const char*> defaults, bool vec3) const
{
    std::string name;
    if (!given.empty()) {
        if (!grid(given)) {
            std::vector<std::string> names;
            for (const auto& g : *mGrids) names.push_back(g->getName());
            const std::string near = closestMatch(given, names);
            const SourceLocation at = mSource.grids.where.file.empty()
                                          ? SourceLocation{mSource.file.string()}
                                          : mSource.grids.where;
            throw UserError(at, "grids." + part + ": volume '" + mSource.file.string() +
                                    "' has no grid '" + given + "'" +
                                    (near.empty() ? "" : "; did you mean '" + near + "'?") +
                                    " (it holds: " + joined(names) + ")");
        }
        name = given;
    } else {
        for (const char* d : defaults)
            if (grid(d)) {
                name = d;
                break;
            }
    }
    if (name.empty()) return name;
    const openvdb::GridBase& g = *grid(name);
    if (vec3 ? !isVec3(g) : !isFloat(g))
        throw error("grid '" + name + "' is of type " + g.valueType() + "; the " + part +
                    " needs a " + (vec3 ? "vec3s" : "float") + " grid");
    return name;
}

/// The picked grids' world bounds and the finest voxel size, under the object's placement.
void VolumeFile::measure()
{
    VolumeFileInfo& i = mInfo;
    i.voxelSize = std::numeric_limits<double>::max();
    i.worldMin = Vec3d(std::numeric_limits<double>::max());
    i.worldMax = Vec3d(-std::numeric_limits<double>::max());
    for (const std::string& name : {i.density, i.sdf}) {
        if (name.empty()) continue;
        const openvdb::GridBase& g = *grid(name);
        const openvdb::math::Transform::Ptr xf = placedTransform(g.transform(), mSource.transform);
        const Vec3d size = xf->voxelSize();
        i.voxelSize = std::min({i.voxelSize, size.x(), size.y(), size.z()});
        const openvdb::CoordBBox box = g.evalActiveVoxelBoundingBox();
        if (box.empty()) continue;
        for (int k = 0; k < 8; ++k) {
            const Vec3d index((k & 1) ? box.max().x() + 0.5 : box.min().x() - 0.5,
                              (k & 2) ? box.max().y() + 0.5 : box.min().y() - 0.5,
                              (k & 4) ? box.max().z() + 0.5 : box.min().z() - 0.5);
            const Vec3d w = xf->indexToWorld(index);
            i.worldMin = minComponent(i.worldMin, w);
            i.worldMax = maxComponent(i.worldMax, w);
            i.empty = false;
        }
    }
}

openvdb::GridBase::Ptr VolumeFile::read(const std::string& name) const
{
    const openvdb::GridBase::Ptr g = grid(name);
    if (!g) throw error("has no grid '" + name + "'");
    openvdb::GridBase::Ptr placed = g->copyGrid(); // shares the tree
    placed->setTransform(placedTransform(g->transform(), mSource.transform));
    return placed;
}

} // namespace volmorph::detail
