#include "ScriptScene.h"

#include <volmorph/Frames.h>
#include <volmorph/Voxelize.h>
#include <volmorph/core/Version.h>

#include <chrono>
#include <sstream>
#include <stdexcept>

namespace volmorph::script {

// ---- WatchedInterrupter, ScriptJob ----

void WatchedInterrupter::start(const char* name)
{
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mStage = name ? name : "";
    }
    mPercent.store(-1, std::memory_order_relaxed);
    Interrupter::start(name);
}

void WatchedInterrupter::end()
{
    Interrupter::end();
    mPercent.store(-1, std::memory_order_relaxed);
}

bool WatchedInterrupter::wasInterrupted(int percent)
{
    if (percent >= 0) mPercent.store(percent, std::memory_order_relaxed);
    return Interrupter::wasInterrupted(percent);
}

std::string WatchedInterrupter::stage() const
{
    std::lock_guard<std::mutex> lock(mMutex);
    return mStage;
}

ScriptJob::ScriptJob(std::function<void(Interrupter&)> work)
{
    mThread = std::thread([this, work = std::move(work)] {
        std::exception_ptr error;
        try {
            work(mInterrupter);
        } catch (...) {
            error = std::current_exception();
        }
        std::lock_guard<std::mutex> lock(mMutex);
        mError = error;
        mDone = true;
        mDoneSignal.notify_all();
    });
}

ScriptJob::~ScriptJob()
{
    cancel();
    if (mThread.joinable()) mThread.join();
}

bool ScriptJob::wait(double seconds)
{
    // Only waits: the thread is joined by the destructor alone (two callers may wait at once).
    std::unique_lock<std::mutex> lock(mMutex);
    if (seconds < 0.0)
        mDoneSignal.wait(lock, [this] { return mDone; });
    else
        mDoneSignal.wait_for(lock, std::chrono::duration<double>(seconds),
                             [this] { return mDone; });
    return mDone;
}

void ScriptJob::rethrow() const
{
    std::lock_guard<std::mutex> lock(mMutex);
    if (mError) std::rethrow_exception(mError);
}

// ---- ScriptScene ----

/// What the scene's SceneMorphs and renderer hold as their interrupter: the running job's.
struct ScriptScene::Forwarder : Interrupter {
    Interrupter* target = nullptr;
    void start(const char* name) override
    {
        if (target) target->start(name);
    }
    void end() override
    {
        if (target) target->end();
    }
    bool wasInterrupted(int percent) override { return target && target->wasInterrupted(percent); }
};

namespace {

/// Points `forward` at `target` for one call.
class Forwarding {
public:
    Forwarding(Interrupter*& slot, Interrupter& target) : mSlot(slot) { mSlot = &target; }
    ~Forwarding() { mSlot = nullptr; }
    Forwarding(const Forwarding&) = delete;
    Forwarding& operator=(const Forwarding&) = delete;

private:
    Interrupter*& mSlot;
};

/// A side as the scene file writes it, every digit kept: { origin = [...], axes = [[x], [y]],
/// scale = [...] }.
std::string elementToml(const FeatureElement& e)
{
    auto v = [](const Vec3d& a) { return tomlArray({a[0], a[1], a[2]}); };
    return "{ origin = " + v(e.origin) + ", axes = [" + v(e.xAxis) + ", " + v(e.yAxis) +
           "], scale = " + v(e.scale) + " }";
}

/// Sets one side's `field` in pair `index` (from 1); a side written in short form (its origin
/// alone) is written whole.
void setSideField(SceneDocument& doc, int index, const char* side, const char* field,
                  const std::string& value, const FeatureElement& whole)
{
    const std::string key = "pair[" + std::to_string(index) + "]." + side;
    try {
        doc.set(key + "." + field, value);
    } catch (const std::invalid_argument&) {
        doc.set(key, elementToml(whole));
    }
}

void setSide(SceneDocument& doc, int index, const char* side, const FeatureElement& was,
             const FeatureElement& now)
{
    auto v = [](const Vec3d& a) { return tomlArray({a[0], a[1], a[2]}); };
    if (now.origin != was.origin) setSideField(doc, index, side, "origin", v(now.origin), now);
    if (now.xAxis != was.xAxis || now.yAxis != was.yAxis)
        setSideField(doc, index, side, "axes", "[" + v(now.xAxis) + ", " + v(now.yAxis) + "]", now);
    if (now.scale != was.scale) setSideField(doc, index, side, "scale", v(now.scale), now);
}

} // namespace

ScriptScene::ScriptScene(std::filesystem::path path)
    : mPath(std::move(path)), mDocument(SceneDocument::read(mPath)),
      mScene(parseScene(mDocument.text(), mPath)), mForward(std::make_unique<Forwarder>())
{
}

ScriptScene::~ScriptScene() = default;

std::vector<int> ScriptScene::frames() const
{
    return selectFrames(mScene.frames, "");
}

void ScriptScene::requireFrame(int frame) const
{
    if (frame < mScene.frames.first || frame > mScene.frames.last)
        throw UserError(SourceLocation{mPath.string()},
                        "frame " + std::to_string(frame) + " is outside the scene's frames " +
                            std::to_string(mScene.frames.first) + "-" +
                            std::to_string(mScene.frames.last));
}

void ScriptScene::reset()
{
    mMorph.reset();
    mRenderMorph.reset();
    mRender.reset();
}

openvdb::GridPtrVec ScriptScene::morph(int frame, GridNames names,
                                       const std::filesystem::path& file, Interrupter& interrupter)
{
    requireFrame(frame);
    const Forwarding forwarding(mForward->target, interrupter);
    try {
        if (!mMorph)
            mMorph = std::make_unique<cli::SceneMorph>(mScene, cli::CacheArgs{}, *mForward,
                                                       cli::morphCommandOptions(mScene), true);
        const VolumeSet volumes = mMorph->frame(frame);
        const VdbWriteOptions options = cli::frameVdbOptions(mScene, mPath, frame, names, false);
        if (!file.empty()) {
            if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
            writeVolumeSet(volumes, file, options);
        }
        return namedGrids(volumes, options);
    } catch (const Interrupted&) {
        reset();
        throw;
    }
}

render::Image ScriptScene::render(int frame, const std::filesystem::path& file,
                                  Interrupter& interrupter)
{
    requireFrame(frame);
    const Forwarding forwarding(mForward->target, interrupter);
    try {
        if (!mRender) {
            mRender = std::make_unique<cli::SceneRender>(mScene, 0);
            mRender->settings.interrupter = mForward.get();
        }
        if (!mRenderMorph)
            mRenderMorph =
                std::make_unique<cli::SceneMorph>(mScene, cli::CacheArgs{}, *mForward,
                                                  cli::renderMorphOptions(mScene, *mRender), true);
        const auto start = std::chrono::steady_clock::now();
        render::Image image = cli::renderMorphFrame(*mRender, *mRenderMorph, frame);
        if (!file.empty())
            cli::writeFrameExr(image, *mRender, mScene, mPath, frame, file,
                               cli::secondsSince(start));
        return image;
    } catch (const Interrupted&) {
        reset();
        throw;
    }
}

void ScriptScene::setPairs(const std::vector<Pair>& pairs)
{
    SceneDocument next = mDocument;
    const std::vector<Pair>& was = mScene.pairs;
    const size_t common = std::min(was.size(), pairs.size());
    try {
        for (size_t i = 0; i < common; ++i) {
            const int index = int(i) + 1;
            if (pairs[i].type != was[i].type)
                next.set("pair[" + std::to_string(index) + "].type",
                         std::string("\"") + toString(pairs[i].type) + "\"");
            setSide(next, index, "source", was[i].source, pairs[i].source);
            setSide(next, index, "target", was[i].target, pairs[i].target);
        }
        for (size_t i = was.size(); i > pairs.size(); --i) next.removePair(int(i));
        for (size_t i = common; i < pairs.size(); ++i) {
            Pair exact = pairs[i]; // every digit, as the other values
            std::vector<std::string> lines = {
                std::string("type = \"") + toString(exact.type) + "\"",
                "source = " + elementToml(exact.source), "target = " + elementToml(exact.target)};
            next.appendPair(lines);
        }
    } catch (const std::invalid_argument& e) {
        throw UserError(SourceLocation{mPath.string()},
                        std::string("the pairs cannot be written: ") + e.what());
    }
    Scene scene = parseScene(next.text(), mPath); // UserError: nothing changed
    mDocument = std::move(next);
    mScene = std::move(scene);
    reset(); // the in-betweens change with the pairs (the voxels come back from the cache)
}

void ScriptScene::save(const std::filesystem::path& file) const
{
    mDocument.save(file.empty() ? mPath : file);
}

openvdb::GridPtrVec voxelizeMesh(const std::filesystem::path& path, std::optional<double> voxelSize,
                                 std::optional<int> resolution, Interrupter& interrupter)
{
    const Mesh mesh = importMesh(path);
    throwIfInterrupted(&interrupter);
    VoxelizeOptions options;
    options.voxelSize = voxelSize;
    if (resolution) options.resolution = *resolution;
    VoxelizeStats stats;
    const VolumeSet volumes = voxelize(mesh, options, &interrupter, &stats);
    throwIfInterrupted(&interrupter);
    std::ostringstream voxel;
    voxel << stats.voxelSize;
    VdbWriteOptions write;
    write.metadata = {{"volmorph_source", std::filesystem::absolute(path).string()},
                      {"volmorph_voxel_size", voxel.str()},
                      {"volmorph_version", versionString()}};
    return namedGrids(volumes, write);
}

} // namespace volmorph::script
