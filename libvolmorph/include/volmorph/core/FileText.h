// Reading a whole file as it is on disk (scene files, the editor's page): the one reader those
// share, where AtomicFile.h is the one writer.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace volmorph {

/// The file's bytes; nothing when it is not a regular file that can be read (missing, a folder,
/// no permission).
std::optional<std::string> readFileText(const std::filesystem::path& path);

} // namespace volmorph
