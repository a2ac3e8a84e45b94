// Reading a whole .vdb file safely. OpenVDB's io::File does not check its reads: on a truncated
// file it went on with sizes it never read (seen: a 4 GB grid name, 15 GB of memory, differing from
// run to run). readVdbGrids reads through io::Stream from a stream that throws at the first read
// past the file's end, so a truncated file fails at once, the same way every time.
#pragma once

#include <openvdb/openvdb.h>

#include <filesystem>

namespace volmorph {

/// Every grid of the .vdb file at `path`, voxels included. Throws std::runtime_error saying why
/// it cannot ("cannot open the file", "it ends early: truncated or damaged", OpenVDB's reason).
openvdb::GridPtrVecPtr readVdbGrids(const std::filesystem::path& path);

} // namespace volmorph
