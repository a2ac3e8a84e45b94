// The scene's [render] table turned into the renderer's objects, shared by `render` and `preview`.
#pragma once

#include <volmorph/Scene.h>
#include <volmorph/VolumeSet.h>
#include <volmorph/render/Camera.h>
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include <memory>
#include <vector>

namespace volmorph::render {
class EnvironmentMap;
}

namespace volmorph::cli {

/// The props imported and placed, for Embree (null for none); UserError at a prop's `mesh` key
/// when it cannot be read.
std::shared_ptr<const render::Props> importProps(const std::vector<PropSpec>& props);

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

    /// The seconds either side of a frame that the shutter reaches (0: no motion blur).
    double shutterReachSeconds() const;

private:
    RenderSpec mSpec;
    std::shared_ptr<const render::Props> mProps; ///< settings.props points here
    /// Per light of the scene: its sky map, read once for the sequence (null: none).
    std::vector<std::shared_ptr<const render::EnvironmentMap>> mMaps;
    double mFps;
    int mWidth;
};

} // namespace volmorph::cli
