#include <volmorph/core/Diagnostics.h>
#include <volmorph/VolumeSet.h>

#include <volmorph/core/AtomicFile.h>
#include <volmorph/core/VdbRead.h>
#include "export/VdbFile.h"

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include <cstdio>
#include <mutex>
#include <set>

namespace volmorph {
namespace {

void initializeOpenVdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

} // namespace

std::string presetName(const std::string& grid, GridNames names)
{
    if (names == GridNames::Houdini) {
        if (grid == kSdfGridName) return "surface";
        if (grid == "velocity") return "vel";
    } else if (names == GridNames::Blender) {
        if (grid == kColorGridName) return "color";
        if (grid == "vel") return "velocity";
    }
    return grid;
}

openvdb::GridPtrVec namedGrids(const VolumeSet& volumes, const VdbWriteOptions& options)
{
    openvdb::GridPtrVec all = {volumes.sdf, volumes.density, volumes.color, volumes.velocity};
    for (const auto& [name, grid] : volumes.extras) all.push_back(grid);
    openvdb::GridPtrVec grids;
    std::set<std::string> taken;
    for (const openvdb::GridBase::Ptr& g : all) {
        if (!g) continue;
        // A shallow copy (the tree shared) carries the file's names and metadata.
        openvdb::GridBase::Ptr out = g->copyGrid();
        std::string name = presetName(g->getName(), options.names);
        // A carried grid whose name a part takes under the preset (a "color" grid beside Cd, for
        // Blender) keeps its data under a suffixed name.
        while (!taken.insert(name).second) name += "_carried";
        out->setName(name);
        out->setSaveFloatAsHalf(options.half);
        for (const auto& [key, value] : options.metadata)
            out->insertMeta(key, openvdb::StringMetadata(value));
        grids.push_back(out);
    }
    return grids;
}

void writeVolumeSet(const VolumeSet& volumes, const std::filesystem::path& path,
                    const VdbWriteOptions& options)
{
    initializeOpenVdb();
    const openvdb::GridPtrVec grids = namedGrids(volumes, options);
    writeAtomically(path, "volume file", [&grids](const std::filesystem::path& temporary) {
        detail::writeVdbChecked(temporary, openvdb::GridCPtrVec(grids.begin(), grids.end()),
                                openvdb::MetaMap());
    });
}

namespace detail {

void writeVdbChecked(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids,
                     const openvdb::MetaMap& meta)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(std::strerror(errno));
    openvdb::io::Stream stream(out);
    stream.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    stream.write(grids, meta);
    out.flush();
    const bool written = bool(out);
    const int error = errno;
    out.close();
    if (!written || out.fail())
        throw std::runtime_error(std::string("write failed: ") +
                                 (error ? std::strerror(error) : "unknown reason"));
}

} // namespace detail

VolumeSet readVolumeSet(const std::filesystem::path& path)
{
    openvdb::GridPtrVecPtr grids;
    try {
        grids = readVdbGrids(path);
    } catch (const std::exception& e) {
        throw UserError(SourceLocation{path.string()},
                        std::string("cannot read volume file (") + e.what() + ")");
    }
    VolumeSet out;
    for (const openvdb::GridBase::Ptr& g : *grids) setPartByName(out, g);
    return out;
}

} // namespace volmorph
