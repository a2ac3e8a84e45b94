#include "SceneRender.h"

#include "KeyframeTrack.h"

#include <volmorph/Mesh.h>
#include <volmorph/core/Diagnostics.h>
#include <volmorph/render/EnvironmentMap.h>
#include <volmorph/render/Output.h>

#include <algorithm>
#include <cmath>

namespace volmorph::cli {

namespace {

render::Camera sceneCamera(const CameraSpec& c, const RenderSpec& r, int width)
{
    const int w = width > 0 ? width : r.width;
    const int h =
        width > 0 ? std::max(1, int(std::lround(double(r.height) * w / r.width))) : r.height;
    return render::Camera(c.projection == Projection::Orthographic
                              ? render::Camera::Projection::Orthographic
                              : render::Camera::Projection::Perspective,
                          c.eye, c.lookat, c.up, c.fovDegrees, c.orthoWidth, w, h);
}

} // namespace

std::vector<render::PropMesh> importPropMeshes(const std::vector<PropSpec>& props)
{
    std::vector<render::PropMesh> meshes;
    for (const PropSpec& spec : props) {
        const Mesh mesh = importMesh(spec.mesh, spec.transform, spec.where);
        render::PropMesh prop;
        prop.points = mesh.points;
        prop.triangles = mesh.triangles;
        prop.color = spec.color;
        prop.role = spec.holdout         ? render::PropMesh::Role::Holdout
                    : spec.shadowCatcher ? render::PropMesh::Role::ShadowCatcher
                                         : render::PropMesh::Role::Diffuse;
        meshes.push_back(std::move(prop));
    }
    return meshes;
}

std::shared_ptr<const render::Props> importProps(const std::vector<PropSpec>& props)
{
    std::vector<render::PropMesh> meshes = importPropMeshes(props);
    if (meshes.empty()) return nullptr;
    return std::make_shared<const render::Props>(std::move(meshes));
}

render::PropMesh subjectMesh(const SurfaceFrame& frame, double albedo, bool moving)
{
    render::PropMesh mesh;
    mesh.subject = true;
    mesh.triangles = frame.triangles;
    mesh.points.reserve(frame.points.size());
    for (const Vec3d& p : frame.points) mesh.points.emplace_back(p);
    mesh.color = Vec3d(albedo);
    for (const Vec3f& c : frame.colors) mesh.colors.push_back(c * float(albedo));
    std::vector<Vec3d> normals(frame.points.size(), Vec3d(0.0));
    for (const Vec3I& t : frame.triangles) {
        const Vec3d& a = frame.points[t[0]];
        // The cross product's length is twice the area: area-weighted.
        const Vec3d n = (frame.points[t[1]] - a).cross(frame.points[t[2]] - a);
        for (int k = 0; k < 3; ++k) normals[t[k]] += n;
    }
    for (const Vec3d& n : normals) mesh.normals.emplace_back(n);
    if (moving)
        for (const Vec3d& v : frame.velocity) mesh.velocities.emplace_back(v);
    return mesh;
}

std::shared_ptr<const render::EnvironmentMap> readSkyMap(const LightSpec& light)
{
    if (light.map.empty()) return nullptr;
    try {
        return render::EnvironmentMap::read(light.map);
    } catch (const std::exception& e) {
        throw UserError(light.mapWhere,
                        "cannot read the sky map " + light.map.string() + " (" + e.what() + ")");
    }
}

SceneRender::SceneRender(const Scene& scene, int threads, int width)
    : mSpec(scene.render), mFps(scene.frames.fps), mWidth(width)
{
    const RenderSpec& r = scene.render;
    medium.extinction = r.extinction;
    medium.albedo = r.albedo;
    medium.anisotropy = r.anisotropy;
    medium.emission = r.emission;
    settings.samples = r.samples;
    settings.noise = r.noise;
    settings.denoise = r.denoise;
    settings.stepVoxels = r.stepVoxels;
    settings.shadowCacheVoxels = r.shadowCacheVoxels;
    settings.bounces = r.bounces;
    settings.layers = r.layers;
    settings.seed = r.seed;
    settings.threads = threads;
    mPropMeshes = importPropMeshes(scene.props);
    if (!mPropMeshes.empty()) mProps = std::make_shared<const render::Props>(mPropMeshes);
    settings.props = mProps.get();
    for (const LightSpec& light : r.lights) mMaps.push_back(readSkyMap(light));
}

render::Camera SceneRender::camera(double frame) const
{
    return sceneCamera(cameraAt(mSpec.camera, frame), mSpec, mWidth);
}

std::vector<render::Light> SceneRender::lights(double frame) const
{
    std::vector<render::Light> lights;
    for (size_t i = 0; i < mSpec.lights.size(); ++i) {
        const LightSpec l = lightAt(mSpec.lights[i], frame);
        render::Light light;
        light.type = l.type == LightType::Point         ? render::Light::Type::Point
                     : l.type == LightType::Environment ? render::Light::Type::Environment
                                                        : render::Light::Type::Directional;
        light.direction = l.direction;
        light.position = l.position;
        light.color = l.color;
        light.intensity = l.intensity;
        light.angle = l.angleRadians;
        light.map = mMaps[i];
        lights.push_back(light);
    }
    return lights;
}

render::Image SceneRender::renderFrame(const VolumeSet& volumes, int frame) const
{
    return render(volumes, frame, settings);
}

render::Image SceneRender::renderFrame(const SurfaceFrame& surface, int frame) const
{
    std::vector<render::PropMesh> meshes = mPropMeshes;
    meshes.push_back(subjectMesh(surface, medium.albedo, mSpec.motionBlur()));
    const render::Props props(std::move(meshes));
    render::RenderSettings s = settings;
    s.props = &props;
    VolumeSet nothing; // no volume: the surface alone among the props
    nothing.density = openvdb::FloatGrid::create(0.0f);
    return render(nothing, frame, s);
}

render::Image SceneRender::render(const VolumeSet& volumes, int frame,
                                  render::RenderSettings s) const
{
    s.frame = frame;
    if (!mSpec.motionBlur())
        return render::renderVolume(*volumes.density, volumes.color.get(), camera(frame),
                                    lights(frame), medium, s);
    std::vector<render::ShutterTime> times;
    for (double offset :
         render::shutterOffsets(mSpec.shutter.first, mSpec.shutter.second, s.samples))
        times.push_back({offset / mFps, camera(frame + offset), lights(frame + offset)});
    s.centreSingleSample = false; // each time's sample anywhere in the pixel: antialiased
    // Without a vel grid (a single frame: no frame rate) the volume stands still: the camera and
    // lights still blur.
    return render::renderMotionBlurred(*volumes.density, volumes.color.get(),
                                       volumes.velocity.get(), times, medium, s);
}

double SceneRender::shutterReachSeconds() const
{
    if (!mSpec.motionBlur()) return 0.0;
    return std::max(std::abs(mSpec.shutter.first), std::abs(mSpec.shutter.second)) / mFps;
}

MorphOptions renderMorphOptions(const Scene& scene, const SceneRender& view)
{
    MorphOptions options;
    if (scene.render.motionBlur()) { // the vel grid, over the shutter's reach
        options.secondsPerUnitT = scene.frames.secondsPerUnitT();
        options.velocityReachSeconds = view.shutterReachSeconds();
    }
    return options;
}

void writeFrameExr(const render::Image& image, const SceneRender& view, const Scene& scene,
                   const std::filesystem::path& scenePath, int frame,
                   const std::filesystem::path& file, double seconds)
{
    render::ExrOptions exr;
    exr.frame = frame;
    exr.samples = scene.render.samples;
    exr.noiseTarget = view.settings.noise;
    exr.renderSeconds = seconds;
    exr.metadata["volmorph:scene"] = std::filesystem::absolute(scenePath).string();
    exr.metadata["volmorph:t"] = fmt(scene.frames.t(frame));
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    render::writeExr(image, view.camera(frame), file, exr);
}

render::Image renderMorphFrame(const SceneRender& view, SceneMorph& morph, int frame,
                               const std::function<void()>& morphed)
{
    if (morph.surfaceMode()) {
        const SurfaceFrame surface = morph.surfaceFrame(frame);
        if (morphed) morphed();
        return view.renderFrame(surface, frame);
    }
    const VolumeSet volumes = morph.frame(frame);
    if (morphed) morphed();
    return view.renderFrame(volumes, frame);
}

} // namespace volmorph::cli
