// A checked .vdb writer for the engine's outputs (frames, cache entries).
#pragma once

#include <openvdb/openvdb.h>

#include <filesystem>

namespace volmorph::detail {

/// Writes `grids` (and file-level `meta`) as a .vdb file at `path` (Blosc, active mask), checking
/// the stream: OpenVDB's io::File does not report a failed write (a full disk left a truncated
/// file). Throws std::runtime_error with the reason. Call it inside writeAtomically. Defined in
/// VolumeSetFile.cpp.
void writeVdbChecked(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids,
                     const openvdb::MetaMap& meta);

} // namespace volmorph::detail
