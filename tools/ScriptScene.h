// A scene as a script drives it (the Python module, tools/python): the same morph and render as
// `volmorph morph` and `volmorph render`, a frame at a time, and the scene's feature pairs read and
// written back with every other byte of the file kept. The module only binds this.
//
// Long work (a morph, a render, a voxelization) runs as a ScriptJob on a thread of its own, so that
// the caller's thread stays free: Python's main thread waits on the job a few hundredths of a
// second at a time, runs its signal handlers in between, and cancels the job on Ctrl-C. A job stops
// within a second of cancel() (every stage polls the interrupter), and the scene is usable
// afterwards.
#pragma once

#include "SceneMorph.h"
#include "SceneRender.h"

#include <volmorph/SceneDocument.h>

#include <condition_variable>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace volmorph::script {

/// An interrupter whose stage and percentage another thread can read (for a progress callback).
class WatchedInterrupter : public Interrupter {
public:
    void start(const char* name = nullptr) override;
    void end() override;
    bool wasInterrupted(int percent = -1) override;

    std::string stage() const;
    int percent() const { return mPercent.load(std::memory_order_relaxed); }

private:
    mutable std::mutex mMutex;
    std::string mStage;
    std::atomic<int> mPercent{-1};
};

/// `work` run on its own thread with an interrupter of its own.
class ScriptJob {
public:
    explicit ScriptJob(std::function<void(Interrupter&)> work);
    /// Cancels and waits: a job never outlives its owner.
    ~ScriptJob();
    ScriptJob(const ScriptJob&) = delete;
    ScriptJob& operator=(const ScriptJob&) = delete;

    /// Waits up to `seconds` (negative: until done); true when the work is done.
    bool wait(double seconds);
    /// Asks the work to stop (it throws Interrupted at its next check, within a second).
    void cancel() { mInterrupter.requestStop(); }
    bool cancelled() const { return mInterrupter.stopRequested(); }
    /// After wait() said done: rethrows what the work threw, if anything.
    void rethrow() const;

    std::string stage() const { return mInterrupter.stage(); }
    int percent() const { return mInterrupter.percent(); }

private:
    WatchedInterrupter mInterrupter;
    mutable std::mutex mMutex;
    std::condition_variable mDoneSignal;
    bool mDone = false;
    std::exception_ptr mError;
    std::thread mThread;
};

/// A feature pair as a script sees it: the scene's own FeaturePairSpec.
using Pair = FeaturePairSpec;

class ScriptScene {
public:
    /// Reads and validates `path` (UserError with every problem, each at file:line:col).
    explicit ScriptScene(std::filesystem::path path);
    ~ScriptScene();

    const Scene& scene() const { return mScene; }
    const std::filesystem::path& path() const { return mPath; }
    /// The scene's frame numbers, in order.
    std::vector<int> frames() const;

    /// Frame `frame`'s in-between, its grids named by `names` and carrying the metadata `volmorph
    /// morph` writes; written to `file` as that command writes it when `file` is not empty. Runs on
    /// a job's thread with its interrupter. Throws UserError for a frame outside the scene's.
    openvdb::GridPtrVec morph(int frame, GridNames names, const std::filesystem::path& file,
                              Interrupter& interrupter);
    /// Frame `frame` rendered as `volmorph render` renders it; written to `file` (an EXR with its
    /// layers) when not empty. Runs on a job's thread.
    render::Image render(int frame, const std::filesystem::path& file, Interrupter& interrupter);
    /// Forgets the morphs and the renderer made so far (after a job was cancelled in them: the
    /// next call makes them again, the voxels through the cache).
    void reset();

    /// The source and target meshes placed as the scene places them (world units); a side that
    /// is a volume is an empty mesh. UserError at a `mesh` key that cannot be read.
    SceneMeshes sideMeshes() const { return importSceneMeshes(mScene); }

    /// The pairs as the file holds them now.
    const std::vector<Pair>& pairs() const { return mScene.pairs; }
    /// Makes `pairs` the scene's: each changed value written where the old one is, pairs added
    /// after the last, removed ones taken out; then the scene validated. Throws UserError (and
    /// changes nothing) when the result is not a valid scene.
    void setPairs(const std::vector<Pair>& pairs);
    /// The scene's text as edited.
    const std::string& text() const { return mDocument.text(); }
    /// Writes the text to `file` (empty: the scene's own file), atomically.
    void save(const std::filesystem::path& file) const;

private:
    void requireFrame(int frame) const;

    std::filesystem::path mPath;
    SceneDocument mDocument;
    Scene mScene;
    // Made on first use, on a job's thread: the morph as `volmorph morph` makes it (its vel grid
    // over half a frame), and as `volmorph render` does (over the shutter) with the renderer.
    std::unique_ptr<cli::SceneMorph> mMorph, mRenderMorph;
    std::unique_ptr<cli::SceneRender> mRender;
    // The interrupter each SceneMorph was made with is the job's that made it; a later job's
    // stops it through this one, which forwards.
    struct Forwarder;
    std::unique_ptr<Forwarder> mForward;
};

/// Voxelizes the mesh at `path` as `volmorph voxelize` does (grids sdf, density, Cd), at
/// `voxelSize` world units or `resolution` voxels across when given. Throws UserError naming the
/// file when it cannot be read.
openvdb::GridPtrVec voxelizeMesh(const std::filesystem::path& path, std::optional<double> voxelSize,
                                 std::optional<int> resolution, Interrupter& interrupter);

} // namespace volmorph::script
