#include <volmorph/Frames.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace volmorph;

namespace {

FramesSpec range(int first, int last)
{
    FramesSpec f;
    f.first = first;
    f.last = last;
    return f;
}

std::string errorOf(const FramesSpec& f, const std::string& spec)
{
    try {
        selectFrames(f, spec);
    } catch (const UserError& e) {
        return e.diagnostics().at(0).str();
    }
    return "";
}

} // namespace

TEST(Frames, SpecsAsVfxToolsWriteThem)
{
    const FramesSpec f = range(1, 100);
    EXPECT_EQ(selectFrames(f, "").size(), 100u);
    EXPECT_EQ(selectFrames(f, "1-10"), (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
    EXPECT_EQ(selectFrames(f, "1-100x25"), (std::vector<int>{1, 26, 51, 76}));
    EXPECT_EQ(selectFrames(f, "1,5,10-12"), (std::vector<int>{1, 5, 10, 11, 12}));
    EXPECT_EQ(selectFrames(f, "3,2,3"), (std::vector<int>{3, 2})); // order kept, repeats dropped
}

TEST(Frames, PickingFramesNeverChangesTheirTime)
{
    const FramesSpec f = range(1, 48);
    const std::vector<int> chunk = selectFrames(f, "11-20");
    EXPECT_DOUBLE_EQ(f.t(chunk.front()), 10.0 / 47.0);
    EXPECT_DOUBLE_EQ(f.t(chunk.back()), 19.0 / 47.0);
}

TEST(Frames, BadSpecsAreUserErrors)
{
    const FramesSpec f = range(1, 24);
    EXPECT_EQ(errorOf(f, "30"), "frames: frame 30 is outside the scene's range 1-24");
    EXPECT_EQ(errorOf(f, "0-3"), "frames: frame 0 is outside the scene's range 1-24");
    EXPECT_NE(errorOf(f, "a-b").find("cannot read the frame spec \"a-b\""), std::string::npos);
    EXPECT_NE(errorOf(f, "1-2,x").find("cannot read the frame spec"), std::string::npos);
}

TEST(Frames, PatternsPadLikeHoudiniAndPrintf)
{
    EXPECT_EQ(frameFileName("out/f.####.exr", 42), "out/f.0042.exr");
    EXPECT_EQ(frameFileName("out/f.#.exr", 42), "out/f.42.exr");
    EXPECT_EQ(frameFileName("out/f.%04d.exr", 7), "out/f.0007.exr");
    EXPECT_EQ(frameFileName("out/f.%d.exr", 7), "out/f.7.exr");
    EXPECT_EQ(frameFileName("out/f.####.exr", -3), "out/f.-003.exr");
    EXPECT_EQ(frameFileName("out/still.exr", 5), "out/still.exr");
}

TEST(Frames, PatternChecks)
{
    EXPECT_EQ(checkFramePattern("a.####.exr"), "");
    EXPECT_EQ(checkFramePattern("a.%04d.exr"), "");
    EXPECT_EQ(checkFramePattern("100%%/a.%d.exr"), "");
    EXPECT_NE(checkFramePattern("a.##.b.##.exr"), "");
    EXPECT_NE(checkFramePattern("a.%s.exr"), "");
    EXPECT_NE(checkFramePattern("a.%d.%d.exr"), "");
}

TEST(Frames, ChunksCoverEveryFrameOnceInOrder)
{
    EXPECT_EQ(formatFrames({1, 2, 3, 5, 7, 8}), "1-3,5,7-8");
    EXPECT_EQ(formatFrames({-3, -2, 4}), "-3--2,4");
    EXPECT_EQ(formatFrames({}), "");
    for (int n : {1, 7, 24, 25}) {
        std::vector<int> frames;
        for (int f = 0; f < n; ++f) frames.push_back(10 + 2 * f);
        for (int size : {1, 5, 24, 100}) {
            const int chunks = chunkCount(frames, size);
            EXPECT_EQ(chunks, (n + size - 1) / size);
            std::vector<int> all;
            for (int i = 0; i < chunks; ++i) {
                const std::vector<int> c = chunkFrames(frames, size, i);
                EXPECT_FALSE(c.empty());
                EXPECT_LE(int(c.size()), size);
                all.insert(all.end(), c.begin(), c.end());
            }
            EXPECT_EQ(all, frames) << n << " frames in chunks of " << size;
            EXPECT_TRUE(chunkFrames(frames, size, chunks).empty());
        }
    }
}

TEST(Frames, PlaceholdersAndSequencesOnDisk)
{
    EXPECT_TRUE(hasFramePlaceholder("fx.####.vdb"));
    EXPECT_TRUE(hasFramePlaceholder("fx.%04d.vdb"));
    EXPECT_TRUE(hasFramePlaceholder("fx.%d.vdb"));
    EXPECT_FALSE(hasFramePlaceholder("fx.vdb"));
    EXPECT_FALSE(hasFramePlaceholder("100%%.vdb")); // a literal percent sign
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("volmorph-seq-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir);
    for (const char* name : {"s.0003.vdb", "s.0001.vdb", "s.7.vdb", "t.0002.vdb"})
        std::ofstream(dir / name) << "x";
    // Only the pattern's own padding counts: s.7.vdb is not frame 7 of s.####.vdb.
    EXPECT_EQ(sequenceFrames((dir / "s.####.vdb").string()), (std::vector<int>{1, 3}));
    EXPECT_TRUE(sequenceFrames((dir / "u.####.vdb").string()).empty());
    EXPECT_TRUE(sequenceFrames((dir / "nowhere" / "s.####.vdb").string()).empty());
    // A sequence's file for an output frame: its own, the one before a gap, the ends held.
    ObjectSpec spec;
    spec.volume = dir / "s.####.vdb";
    spec.volumeFrames = {1, 3};
    EXPECT_EQ(spec.volumeAt(0).filename(), "s.0001.vdb");
    EXPECT_EQ(spec.volumeAt(2).filename(), "s.0001.vdb");
    EXPECT_EQ(spec.volumeAt(3).filename(), "s.0003.vdb");
    EXPECT_EQ(spec.volumeAt(9).filename(), "s.0003.vdb");
    std::filesystem::remove_all(dir);
}
