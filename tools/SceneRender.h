// The scene's [render] table turned into the renderer's objects, shared by `render` and `preview`.
#pragma once

#include "SceneMorph.h"

#include <volmorph/Scene.h>
#include <volmorph/SurfaceMorph.h>
#include <volmorph/VolumeSet.h>
#include <volmorph/render/Camera.h>
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include <functional>
#include <memory>
#include <vector>

namespace volmorph::render {
class EnvironmentMap;
}

namespace volmorph::cli {

/// The props imported and placed; UserError at a prop's `mesh` key when it cannot be read.
std::vector<render::PropMesh> importPropMeshes(const std::vector<PropSpec>& props);
/// The same built for Embree (null for none).
std::shared_ptr<const render::Props> importProps(const std::vector<PropSpec>& props);

/// A surface morph's in-between as the shot's subject (PropMesh::subject): diffuse, its
/// reflectance `albedo` times its vertex colours (white without), shaded smooth (area-weighted
/// vertex normals), moving along its vertex velocities when `moving`.
render::PropMesh subjectMesh(const SurfaceFrame& frame, double albedo, bool moving);

/// The light's sky map read (null without one); UserError at its `map` key when it cannot be.
std::shared_ptr<const render::EnvironmentMap> readSkyMap(const LightSpec& light);

struct SceneRender {
    render::Medium medium;
    render::RenderSettings settings; ///< frame left 0: set it per frame

    /// `width` overrides the scene's image width in pixels (the height follows the aspect ratio).
    /// Imports the scene's props and reads its sky map (UserError at their `mesh` or `map` key
    /// when one cannot be read).
    SceneRender(const Scene& scene, int threads, int width = 0);

    /// The camera and lights at `frame` (their keys interpolated; fractional within a shutter).
    render::Camera camera(double frame) const;
    std::vector<render::Light> lights(double frame) const;

    /// Renders frame `frame` of the morph, `volumes` being that frame's in-between; blurred along
    /// its velocity (if it has a vel grid) and the camera's and lights' motion over render.shutter
    /// when the scene has a shutter.
    render::Image renderFrame(const VolumeSet& volumes, int frame) const;
    /// Renders frame `frame` of a surface morph, `surface` being its in-between, as a surface
    /// (subjectMesh) among the props, blurred along its vertex velocities as above; no volume.
    render::Image renderFrame(const SurfaceFrame& surface, int frame) const;

    /// The seconds either side of a frame that the shutter reaches (0: no motion blur).
    double shutterReachSeconds() const;

private:
    /// renderFrame's work with `s` (its props set) and the frame's volume.
    render::Image render(const VolumeSet& volumes, int frame, render::RenderSettings s) const;

    RenderSpec mSpec;
    std::vector<render::PropMesh> mPropMeshes;   ///< the scene's props, for a surface's shot
    std::shared_ptr<const render::Props> mProps; ///< settings.props points here
    /// Per light of the scene: its sky map, read once for the sequence (null: none).
    std::vector<std::shared_ptr<const render::EnvironmentMap>> mMaps;
    double mFps;
    int mWidth;
};

/// `volmorph render`'s morph options: the vel grid over the shutter's reach when the scene blurs.
MorphOptions renderMorphOptions(const Scene& scene, const SceneRender& view);

/// Writes frame `frame`'s image to `file` as `volmorph render` does (its folders made, the file
/// whole or not at all; the samples, noise target, seconds, scene and t in the header). Throws
/// std::exception when it cannot.
void writeFrameExr(const render::Image& image, const SceneRender& view, const Scene& scene,
                   const std::filesystem::path& scenePath, int frame,
                   const std::filesystem::path& file, double seconds);

/// Frame `frame` of `morph` rendered by `view`: as a surface in surface mode, else its volume;
/// `morphed` (may be empty) is called between the morph and the render.
render::Image renderMorphFrame(const SceneRender& view, SceneMorph& morph, int frame,
                               const std::function<void()>& morphed = {});

} // namespace volmorph::cli
