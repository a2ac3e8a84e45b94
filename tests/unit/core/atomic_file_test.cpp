// The one atomic file writer (core/AtomicFile.h): a file appears at its name only when complete.
#include <volmorph/core/AtomicFile.h>
#include <volmorph/core/Diagnostics.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <unistd.h>

using namespace volmorph;
namespace fs = std::filesystem;

namespace {

fs::path freshFolder(const char* name)
{
    const fs::path dir =
        fs::temp_directory_path() / ("volmorph-atomic-" + std::to_string(getpid()) + "-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

size_t entries(const fs::path& dir)
{
    return size_t(std::distance(fs::directory_iterator(dir), {}));
}

} // namespace

TEST(AtomicFile, TemporaryKeepsTheFolderAndExtension)
{
    const fs::path t = temporaryPathFor("/a/b/frame.0001.exr");
    EXPECT_EQ(t.parent_path(), fs::path("/a/b"));
    EXPECT_EQ(t.extension(), ".exr");
    EXPECT_EQ(t.filename().string(), "frame.0001.partial-" + std::to_string(getpid()) + ".exr");
}

TEST(AtomicFile, CompleteWriteAppearsAtItsName)
{
    const fs::path dir = freshFolder("complete");
    const fs::path file = dir / "out.txt";
    fs::path seen;
    writeAtomically(file, [&](const fs::path& temporary) {
        seen = temporary;
        EXPECT_FALSE(fs::exists(file)); // not before the write completes
        std::ofstream(temporary) << "whole\n";
    });
    EXPECT_EQ(seen, temporaryPathFor(file));
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "whole");
    EXPECT_EQ(entries(dir), 1u);
    fs::remove_all(dir);
}

TEST(AtomicFile, FailedWriteLeavesNothingAndKeepsTheOldFile)
{
    const fs::path dir = freshFolder("failed");
    const fs::path file = dir / "out.txt";
    std::ofstream(file) << "old\n";
    try {
        writeAtomically(file, [&](const fs::path& temporary) {
            std::ofstream(temporary) << "half";
            throw std::runtime_error("disk full");
        });
        FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "disk full");
    }
    EXPECT_EQ(entries(dir), 1u); // the temporary is gone
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "old");
    fs::remove_all(dir);
}

TEST(AtomicFile, UserFacingFailureNamesThePathAndWhat)
{
    const fs::path file = fs::path("/no/such/folder") / "frame.vdb";
    try {
        writeAtomically(file, "volume file", [&](const fs::path& temporary) {
            std::ofstream out(temporary);
            if (!out) throw std::runtime_error("cannot open");
        });
        FAIL() << "no exception";
    } catch (const UserError& e) {
        ASSERT_EQ(e.diagnostics().size(), 1u);
        EXPECT_EQ(e.diagnostics()[0].str(),
                  "/no/such/folder/frame.vdb: cannot write volume file (cannot open)");
    }
}
