#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Version.h>
#include <volmorph/VolumeSet.h>
#include <volmorph/VoxelCache.h>

#include <volmorph/core/AtomicFile.h>
#include "export/VdbFile.h"

#include <OpenImageIO/hash.h>
#include <openvdb/io/File.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

namespace volmorph {
namespace {

/// Bump when the entry's layout changes.
constexpr int kCacheFormat = 2;
constexpr const char* kKeyMeta = "volmorph_cache_key";

std::string fileDigest(const std::filesystem::path& path, const SourceLocation& where)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UserError(where, "cannot read file \"" + path.string() + "\"");
    OIIO::SHA1 sha;
    char buffer[1 << 16];
    while (in) {
        in.read(buffer, sizeof buffer);
        if (in.gcount() > 0) sha.append(buffer, size_t(in.gcount()));
    }
    return sha.digest();
}

/// The digest of the running program, so that any other build (a changed voxelizer included) gets
/// other keys; the version string alone would not see a developer's local change.
const std::string& programDigest()
{
    static const std::string digest = [] {
        std::error_code ec;
        const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
        if (ec) return std::string("unknown");
        try {
            return fileDigest(self, SourceLocation{self.string()});
        } catch (const UserError&) {
            return std::string("unknown");
        }
    }();
    return digest;
}

void describe(std::ostream& s, const char* side, const ObjectSpec& o)
{
    const ObjectTransform& x = o.transform;
    s << side << " translate " << x.translate << " rotate " << x.rotateRadians << " scale "
      << x.scale;
    if (o.color) s << " color " << *o.color;
    if (o.isVolume())
        s << " grids '" << o.grids.density << "' '" << o.grids.sdf << "' '" << o.grids.color << "'";
    s << '\n';
}

/// An entry's grid name: "<side>.<part>" for sdf, density and Cd, "<side>.extra.<name>" for the
/// extras (whose names are the user's).
const std::string kExtra = ".extra.";

/// Files one grid of an entry into its side.
std::string place(VolumeSet& v, const std::string& side, const openvdb::GridBase::Ptr& g)
{
    const std::string name = g->getName().substr(side.size());
    if (name.rfind(kExtra, 0) == 0) {
        g->setName(name.substr(kExtra.size()));
        v.extras[g->getName()] = g;
        return {};
    }
    g->setName(name.substr(1));
    if (!setPartByName(v, g)) return "grid " + g->getName() + " is unknown";
    return {};
}

std::filesystem::path checksumFile(const std::filesystem::path& entry)
{
    return std::filesystem::path(entry).replace_extension(".sha1");
}

/// Reads and checks an entry; returns an empty string and fills `out`, or says what is wrong. The
/// file's SHA-1 must match the one written beside it before OpenVDB reads it: OpenVDB trusts the
/// sizes inside a file, and a truncated one can make it ask for petabytes.
std::string readEntry(const std::filesystem::path& path, const std::string& key, SceneVolumes& out)
{
    std::ifstream sum(checksumFile(path));
    std::string expected;
    if (!(sum >> expected)) return "its checksum file is missing";
    try {
        if (fileDigest(path, SourceLocation{path.string()}) != expected)
            return "its bytes do not match its checksum (truncated or damaged)";
    } catch (const UserError&) {
        return "it cannot be read";
    }
    try {
        openvdb::io::File file(path.string());
        file.open(/*delayLoad*/ false);
        const openvdb::MetaMap::Ptr meta = file.getMetadata();
        const auto stored = meta ? meta->getMetadata<openvdb::StringMetadata>(kKeyMeta) : nullptr;
        if (!stored || stored->value() != key) return "it was written for other inputs";
        for (const openvdb::GridBase::Ptr& g : *file.getGrids()) {
            const bool source = g->getName().rfind("source.", 0) == 0;
            std::string problem =
                place(source ? out.source : out.target, source ? "source" : "target", g);
            if (!problem.empty()) return problem;
        }
        file.close();
        for (const VolumeSet* v : {&out.source, &out.target}) {
            if (!v->density || !v->color) return "a side lacks its density or Cd grid";
            if (v->sdf && v->sdf->getGridClass() != openvdb::GRID_LEVEL_SET)
                return "an sdf is not a level set";
        }
        if (out.source.density->transform() != out.target.density->transform())
            return "source and target grids disagree";
    } catch (const std::exception& e) {
        return std::string("it does not read back (") + e.what() + ")";
    }
    return {};
}

void writeEntry(const std::filesystem::path& path, const std::string& key, const SceneVolumes& v)
{
    openvdb::GridPtrVec grids;
    auto add = [&grids](const openvdb::GridBase::Ptr& g, const std::string& name) {
        openvdb::GridBase::Ptr shallow = g->copyGrid(); // shares the tree, renames the copy
        shallow->setName(name);
        grids.push_back(shallow);
    };
    for (const char* side : {"source", "target"}) {
        const VolumeSet& s = std::string(side) == "source" ? v.source : v.target;
        if (s.sdf) add(s.sdf, std::string(side) + "." + kSdfGridName);
        add(s.density, std::string(side) + "." + kDensityGridName);
        add(s.color, std::string(side) + "." + kColorGridName);
        for (const auto& [name, grid] : s.extras) add(grid, side + kExtra + name);
    }
    openvdb::MetaMap meta;
    meta.insertMeta(kKeyMeta, openvdb::StringMetadata(key));
    std::filesystem::create_directories(path.parent_path());
    writeAtomically(path, "voxel cache entry", [&](const std::filesystem::path& temporary) {
        detail::writeVdbChecked(temporary, openvdb::GridCPtrVec(grids.begin(), grids.end()), meta);
    });
    // The checksum last: a reader that finds it can trust the entry it names.
    const std::string digest = fileDigest(path, SourceLocation{path.string()});
    writeAtomically(checksumFile(path), "voxel cache checksum",
                    [&](const std::filesystem::path& temporary) {
                        std::ofstream out(temporary);
                        out << digest << '\n';
                        out.close();
                        if (!out) throw std::runtime_error("write failed");
                    });
}

} // namespace

std::filesystem::path defaultCacheFolder()
{
    if (const char* v = std::getenv("VOLMORPH_CACHE"); v && *v) return v;
    if (const char* v = std::getenv("XDG_CACHE_HOME"); v && *v)
        return std::filesystem::path(v) / "volmorph";
    if (const char* v = std::getenv("HOME"); v && *v)
        return std::filesystem::path(v) / ".cache" / "volmorph";
    return {};
}

std::string voxelCacheKey(const Scene& sequenced)
{
    const Scene scene = sceneAtFrame(sequenced, sequenced.frames.first);
    std::ostringstream s;
    s.precision(17);
    s << "volmorph voxel cache " << kCacheFormat << " version " << versionString() << " program "
      << programDigest() << '\n';
    for (const auto& [side, o] :
         {std::pair{"source", &scene.source}, std::pair{"target", &scene.target}})
        s << side << (o->isVolume() ? " volume " : " mesh ") << fileDigest(o->file(), o->fileWhere)
          << '\n';
    describe(s, "source", scene.source);
    describe(s, "target", scene.target);
    if (scene.volume.voxelSize) s << "voxel_size " << *scene.volume.voxelSize << '\n';
    if (scene.volume.resolution) s << "resolution " << *scene.volume.resolution << '\n';
    // A fog volume gets a derived level set in sdf mode only.
    if (scene.source.isVolume() || scene.target.isVolume())
        s << "sdf mode "
          << (scene.blend.mode == BlendMode::Sdf || scene.blend.mode == BlendMode::Variational)
          << '\n';
    return OIIO::SHA1::digest(s.str().data(), s.str().size());
}

SceneVolumes voxelizeSceneCached(const Scene& scene, const std::filesystem::path& folder,
                                 Interrupter* interrupter, uint64_t memoryLimitBytes,
                                 CacheReport* report)
{
    CacheReport local;
    CacheReport& r = report ? *report : local;
    r = CacheReport{};
    if (folder.empty()) return voxelizeScene(scene, interrupter, memoryLimitBytes);

    openvdb::initialize();
    const std::string key = voxelCacheKey(scene);
    r.entry = folder / (key + ".vdb");
    std::error_code ec;
    if (std::filesystem::exists(r.entry, ec)) {
        SceneVolumes cached;
        r.problem = readEntry(r.entry, key, cached);
        if (r.problem.empty()) {
            r.outcome = CacheReport::Outcome::Hit;
            // The influence shapes and timing regions are not cached: voxelized each time at the
            // sides' voxel size.
            cached.influences =
                voxelizeInfluences(scene, cached.source.voxelSize(), interrupter, memoryLimitBytes);
            cached.timingRegions =
                loadTimingRegions(scene, cached.source.voxelSize(), interrupter, memoryLimitBytes);
            return cached;
        }
    }
    SceneVolumes volumes = voxelizeScene(scene, interrupter, memoryLimitBytes);
    r.outcome = r.problem.empty() ? CacheReport::Outcome::Stored : CacheReport::Outcome::Rebuilt;
    try {
        writeEntry(r.entry, key, volumes);
    } catch (const std::exception& e) {
        r.storeProblem = e.what();
    }
    return volumes;
}

} // namespace volmorph
