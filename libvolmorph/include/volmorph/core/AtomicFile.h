// Writing an output file so that it appears at its final name only when complete.
#pragma once

#include <volmorph/Diagnostics.h>

#include <openvdb/openvdb.h>

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

namespace volmorph::detail {

/// Calls write(temporary) for a temporary name beside `path` (so the rename is atomic), then renames
/// it to `path`. When write throws or the rename fails, the temporary is removed and a UserError
/// "cannot write <what> (reason)" names `path`.
inline void writeAtomically(const std::filesystem::path& path, const std::string& what,
                            const std::function<void(const std::filesystem::path&)>& write)
{
    const std::filesystem::path temporary = path.string() + ".partial-" + std::to_string(long(getpid()));
    std::string failure;
    try {
        write(temporary);
        std::error_code ec;
        std::filesystem::rename(temporary, path, ec);
        if (ec) failure = ec.message();
    } catch (const std::exception& e) {
        failure = e.what();
    }
    if (failure.empty()) return;
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    throw UserError(SourceLocation{path.string()}, "cannot write " + what + " (" + failure + ")");
}

/// Writes `grids` (and file-level `meta`) as a .vdb file at `path` (Blosc, active mask), checking the
/// stream: OpenVDB's io::File does not report a failed write (a full disk left a truncated file).
/// Throws std::runtime_error with the reason. Defined in VolumeIO.cpp.
void writeVdbChecked(const std::filesystem::path& path, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta);

} // namespace volmorph::detail
