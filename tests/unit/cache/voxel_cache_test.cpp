// The voxel cache (VoxelCache.h): what its key depends on, a miss then a hit giving the same grids,
// a damaged entry rebuilt, an unstorable entry reported without failing the run.
#include <volmorph/Scene.h>
#include <volmorph/VoxelCache.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

using namespace volmorph;

namespace {

namespace fs = std::filesystem;

const fs::path kMeshes = fs::path(VOLMORPH_SOURCE_DIR) / "scenes" / "meshes";

/// A temporary folder holding copies of the small test meshes, removed at the end.
struct Workspace {
    fs::path dir;
    Workspace()
    {
        dir = fs::temp_directory_path() /
              ("volmorph-cache-test-" + std::to_string(getpid()) + "-" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir);
        fs::create_directories(dir);
        fs::copy_file(kMeshes / "sphere.obj", dir / "sphere.obj");
        fs::copy_file(kMeshes / "cube.obj", dir / "cube.obj");
    }
    ~Workspace() { fs::remove_all(dir); }
};

/// A scene of the two meshes in `dir`; the arguments change what the voxels depend on.
Scene scene(const fs::path& dir, double voxelSize = 0.05,
            const std::string& targetColor = "[0.5, 0.5, 0.5]", double translate = 1.5)
{
    const std::string text =
        "[source]\nmesh = \"sphere.obj\"\n"
        "[target]\nmesh = \"cube.obj\"\ncolor = " +
        targetColor + "\ntransform = { translate = [" + std::to_string(translate) +
        ", 0, 0] }\n"
        "[volume]\nvoxel_size = " +
        std::to_string(voxelSize) + "\n[frames]\nrange = \"1-2\"\noutput = \"out.####.exr\"\n";
    return parseScene(text, dir / "scene.toml");
}

/// True when the two grids have the same active voxels and tiles with the same values, bit for bit.
template <typename GridT>
bool sameGrid(const GridT& a, const GridT& b)
{
    if (a.activeVoxelCount() != b.activeVoxelCount() ||
        a.tree().leafCount() != b.tree().leafCount())
        return false;
    if (a.transform() != b.transform()) return false;
    auto bAcc = b.getConstAccessor();
    for (auto it = a.cbeginValueOn(); it; ++it)
        if (!bAcc.isValueOn(it.getCoord()) || bAcc.getValue(it.getCoord()) != *it) return false;
    return true;
}

bool sameVolumes(const VolumeSet& a, const VolumeSet& b)
{
    return sameGrid(*a.sdf, *b.sdf) && sameGrid(*a.density, *b.density) &&
           sameGrid(*a.color, *b.color);
}

} // namespace

TEST(VoxelCache, KeyChangesWithEverythingTheVoxelsDependOn)
{
    Workspace w;
    const std::string key = voxelCacheKey(scene(w.dir));
    EXPECT_EQ(key.size(), 40u);
    EXPECT_EQ(voxelCacheKey(scene(w.dir)), key); // the same inputs, the same key
    EXPECT_NE(voxelCacheKey(scene(w.dir, 0.04)), key);
    EXPECT_NE(voxelCacheKey(scene(w.dir, 0.05, "[0.2, 0.5, 0.5]")), key);
    EXPECT_NE(voxelCacheKey(scene(w.dir, 0.05, "[0.5, 0.5, 0.5]", 1.25)), key);
    // The mesh's bytes, not its name or date: one more comment line changes the key.
    std::ofstream(w.dir / "cube.obj", std::ios::app) << "# edited\n";
    EXPECT_NE(voxelCacheKey(scene(w.dir)), key);
}

TEST(VoxelCache, MissStoresThenHitGivesTheSameGrids)
{
    Workspace w;
    const Scene s = scene(w.dir);
    const fs::path folder = w.dir / "cache";
    CacheReport first, second;
    const SceneVolumes built = voxelizeSceneCached(s, folder, nullptr, 0, &first);
    EXPECT_EQ(first.outcome, CacheReport::Outcome::Stored);
    EXPECT_TRUE(first.storeProblem.empty()) << first.storeProblem;
    EXPECT_TRUE(fs::exists(first.entry));
    EXPECT_EQ(first.entry, folder / (voxelCacheKey(s) + ".vdb"));
    const SceneVolumes read = voxelizeSceneCached(s, folder, nullptr, 0, &second);
    EXPECT_EQ(second.outcome, CacheReport::Outcome::Hit);
    EXPECT_TRUE(read.meshes.source.points.empty()); // a hit imports no mesh
    EXPECT_TRUE(sameVolumes(built.source, read.source));
    EXPECT_TRUE(sameVolumes(built.target, read.target));
    // And no temporary was left beside the entry.
    for (const auto& entry : fs::directory_iterator(folder))
        EXPECT_EQ(entry.path().string().find("partial"), std::string::npos) << entry.path();
}

TEST(VoxelCache, DamagedEntryIsReportedAndRebuilt)
{
    Workspace w;
    const Scene s = scene(w.dir);
    const fs::path folder = w.dir / "cache";
    CacheReport report;
    const SceneVolumes built = voxelizeSceneCached(s, folder, nullptr, 0, &report);
    fs::resize_file(report.entry, fs::file_size(report.entry) / 2); // a truncated entry
    const SceneVolumes rebuilt = voxelizeSceneCached(s, folder, nullptr, 0, &report);
    EXPECT_EQ(report.outcome, CacheReport::Outcome::Rebuilt);
    EXPECT_FALSE(report.problem.empty());
    EXPECT_TRUE(sameVolumes(built.source, rebuilt.source));
    voxelizeSceneCached(s, folder, nullptr, 0, &report); // the rebuilt entry is whole again
    EXPECT_EQ(report.outcome, CacheReport::Outcome::Hit);
}

TEST(VoxelCache, UnstorableEntryIsReportedAndTheVolumesReturned)
{
    Workspace w;
    const fs::path notAFolder = w.dir / "file";
    std::ofstream(notAFolder) << "a file where the cache folder should be\n";
    CacheReport report;
    const SceneVolumes v = voxelizeSceneCached(scene(w.dir), notAFolder, nullptr, 0, &report);
    EXPECT_FALSE(report.storeProblem.empty());
    ASSERT_TRUE(v.source.density);
    EXPECT_GT(v.source.density->activeVoxelCount(), 0u);
}

TEST(VoxelCache, DisabledWithNoFolderAndTheDefaultFollowsTheEnvironment)
{
    Workspace w;
    CacheReport report;
    voxelizeSceneCached(scene(w.dir), fs::path(), nullptr, 0, &report);
    EXPECT_EQ(report.outcome, CacheReport::Outcome::Disabled);
    const char* old = std::getenv("VOLMORPH_CACHE");
    const std::string saved = old ? old : "";
    setenv("VOLMORPH_CACHE", (w.dir / "somewhere").c_str(), 1);
    EXPECT_EQ(defaultCacheFolder(), w.dir / "somewhere");
    if (old)
        setenv("VOLMORPH_CACHE", saved.c_str(), 1);
    else
        unsetenv("VOLMORPH_CACHE");
}
