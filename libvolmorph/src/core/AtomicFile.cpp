#include <volmorph/core/AtomicFile.h>

#include <volmorph/core/Diagnostics.h>

#include <unistd.h>

#include <stdexcept>

namespace volmorph {

std::filesystem::path temporaryPathFor(const std::filesystem::path& path)
{
    return path.parent_path() / (path.stem().string() + ".partial-" +
                                 std::to_string(long(getpid())) + path.extension().string());
}

void writeAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write)
{
    const std::filesystem::path temporary = temporaryPathFor(path);
    std::string failure;
    try {
        write(temporary);
        std::error_code ec;
        std::filesystem::rename(temporary, path, ec);
        if (ec)
            failure = "cannot rename " + temporary.string() + " to " + path.string() + ": " +
                      ec.message();
    } catch (const std::exception& e) {
        failure = e.what();
        if (failure.empty()) failure = "write failed";
    }
    if (failure.empty()) return;
    std::error_code ec;
    std::filesystem::remove(temporary, ec);
    throw std::runtime_error(failure);
}

void writeAtomically(const std::filesystem::path& path, const std::string& what,
                     const std::function<void(const std::filesystem::path& temporary)>& write)
{
    try {
        writeAtomically(path, write);
    } catch (const std::runtime_error& e) {
        throw UserError(SourceLocation{path.string()},
                        "cannot write " + what + " (" + e.what() + ")");
    }
}

} // namespace volmorph
