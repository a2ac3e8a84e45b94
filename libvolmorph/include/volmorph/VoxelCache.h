// An on-disk cache of a scene's voxelized source and target, so that the chunks of a sequence
// rendered on a farm voxelize once, not once per chunk.
//
// An entry is one .vdb file, <folder>/<key>.vdb, holding every grid of both sides ("source.sdf",
// "target.density", "source.extra.temperature", ...), and the SHA-1 of its bytes in
// <folder>/<key>.sha1, checked before OpenVDB reads the entry. The key is the SHA-1 of everything
// the voxels depend on: the cache format, the volmorph version and the bytes of the running program
// (another build never reads this build's entries), the bytes of both mesh or volume files (not of
// files they reference, such as an OBJ's .mtl), both object transforms, colours and grid names,
// the scene's [volume] settings, and with a volume input the blend mode (sdf mode derives a fog's
// level set). A changed mesh or setting therefore misses; an entry
// that does not read back whole, lacks a grid or carries another key is reported and rebuilt, never
// trusted. Entries are written atomically (temporary name, then rename), so chunks racing to fill
// the same entry are safe.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/Scene.h>
#include <volmorph/SceneVolumes.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace volmorph {

/// The default cache folder: $VOLMORPH_CACHE, else $XDG_CACHE_HOME/volmorph, else
/// $HOME/.cache/volmorph; empty (no cache) when none of them is set.
std::filesystem::path defaultCacheFolder();

/// The cache key of `scene`'s voxels (40 hex digits). Reads both input files; throws UserError
/// naming one that cannot be read.
std::string voxelCacheKey(const Scene& scene);

struct CacheReport {
    enum class Outcome { Disabled, Hit, Stored, Rebuilt };
    Outcome outcome = Outcome::Disabled;
    std::filesystem::path entry; ///< the entry's file, when the cache is enabled
    std::string problem;         ///< why an existing entry was rebuilt
    std::string storeProblem;    ///< why the new entry could not be stored (the run goes on)
};

/// voxelizeScene() through the cache in `folder` (empty: no cache). On a hit the meshes are not
/// imported and SceneVolumes::meshes stays empty. Failing to store an entry is not an error: it is
/// reported in `report` and the volumes are returned.
SceneVolumes voxelizeSceneCached(const Scene& scene, const std::filesystem::path& folder,
                                 Interrupter* interrupter = nullptr, uint64_t memoryLimitBytes = 0,
                                 CacheReport* report = nullptr);

} // namespace volmorph
