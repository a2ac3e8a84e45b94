// Writing an output file so that it appears at its final name only when complete: the one writer
// that every output of volmorph goes through (volumes, meshes, cache entries, images).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace volmorph {

/// Calls write(temporary) for a temporary name beside `path` (same folder, so the rename is atomic;
/// same extension, so a writer that picks its format from the name picks the same one), then
/// renames it to `path`. When write throws or the rename fails, the temporary is removed and
/// std::runtime_error says why (`write`'s message, or the rename's). `path` is never touched then.
void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

/// The same, for user-facing outputs: a failure is a UserError naming `path`,
/// "cannot write <what> (<reason>)".
void writeAtomically(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

/// The temporary name writeAtomically uses for `path`: "<stem>.partial-<pid><extension>".
std::filesystem::path temporaryPathFor(const std::filesystem::path& path);

} // namespace volmorph
