// The renderer's outer levels: what one image prepares (empty-space mask, padded leaves, shadows),
// the loop over tiles, and one pixel's samples. What happens along a ray is RayIntegrator.cpp's.
#include <volmorph/render/Renderer.h>

#include <volmorph/core/Interrupter.h>

#include "GridReaders.h"
#include "Majorants.h"
#include "PathTracer.h"
#include "RayIntegrator.h"
#include "Sampling.h"
#include "Shadows.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>

namespace volmorph::render {
namespace {

bool interrupted(openvdb::util::NullInterrupter* interrupter)
{
    return interrupter && interrupter->wasInterrupted();
}

/// Names the stage that starts now to the interrupter (OpenVDB's start/end), for logs.
void stage(openvdb::util::NullInterrupter* interrupter, const char* name)
{
    if (!interrupter) return;
    interrupter->end();
    if (name) interrupter->start(name);
}

/// The pixel (x, y)'s samples averaged: RGB premultiplied, A = 1 - transmittance.
void renderPixel(ThreadReaders& readers, const Camera& camera, const RenderSettings& settings,
                 int x, int y, float* px)
{
    const int samples = std::max(1, settings.samples);
    const int strata = int(std::ceil(std::sqrt(double(samples))));
    double r = 0, g = 0, b = 0, alpha = 0;
    for (int s = 0; s < samples; ++s) {
        Random random(uint64_t(y) * 65536u + uint64_t(x), uint64_t(s),
                      (uint64_t(settings.frame) << 32) ^ settings.seed);
        // One sample goes through the pixel centre (no antialiasing, as vdb_render); more are
        // stratified and jittered over the pixel.
        const double jx = random.next(), jy = random.next();
        const bool centre = samples == 1 && settings.centreSingleSample;
        const double sx = centre ? 0.5 : ((s % strata) + jx) / strata;
        const double sy = centre ? 0.5 : ((s / strata) % strata + jy) / strata;
        const Ray ray = camera.ray(x + sx, y + sy);
        const RaySample sample = readers.in.majorants ? tracePath(readers, ray, random)
                                                      : integrateRay(readers, ray, &random);
        r += sample.L.x();
        g += sample.L.y();
        b += sample.L.z();
        alpha += 1.0 - sample.T;
    }
    px[0] = float(r / samples);
    px[1] = float(g / samples);
    px[2] = float(b / samples);
    px[3] = float(alpha / samples);
}

/// Every pixel of `image`, tiles in parallel. Pixels are independent and each one's samples are
/// seeded by its position, so the result does not depend on how the tiles are scheduled. Stops
/// starting pixels once the interrupter asks (the image is then incomplete).
void renderTiles(const FrameInputs& frame, const Camera& camera, const RenderSettings& settings,
                 Image& image)
{
    tbb::parallel_for(tbb::blocked_range2d<int>(0, image.height, 16, 0, image.width, 16),
                      [&](const tbb::blocked_range2d<int>& tile) {
                          ThreadReaders readers(frame);
                          for (int y = tile.rows().begin(); y != tile.rows().end(); ++y)
                              for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
                                  if (interrupted(settings.interrupter)) return;
                                  renderPixel(readers, camera, settings, x, y, image.at(x, y));
                              }
                      });
}

/// Prepares what every ray reads (the empty-space mask, padded leaves, every light's shadow), then
/// renders the tiles. Throws Interrupted when the interrupter asked to stop.
void renderFrame(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                 const Camera& camera, const std::vector<Light>& lights, const Medium& medium,
                 const RenderSettings& settings, Image& image)
{
    const bool levelSet = medium.kind == Medium::Kind::LevelSet;
    const Props* props = settings.props && !settings.props->empty() ? settings.props : nullptr;
    const double sigmaPerVoxel = medium.extinction * density.voxelSize()[0]; // per index unit
    stage(settings.interrupter, "render: empty-space mask");
    const openvdb::BoolGrid::Ptr mask = rayMask(density, levelSet);
    const PaddedLeaves padded(density.tree());
    if (interrupted(settings.interrupter)) throw Interrupted();
    Vec3d environment(0.0);
    for (const Light& light : lights)
        if (light.type == Light::Type::Environment) environment += light.color * light.intensity;
    // Paths find their transmittance toward the lights by ratio tracking against the majorants;
    // the single-scattering estimator reads shadow maps.
    const bool paths = settings.tracePaths || settings.bounces > 0 || environment != Vec3d(0.0);
    std::vector<Shadow> shadows(lights.size());
    std::unique_ptr<const Majorants> majorants;
    if (paths) {
        stage(settings.interrupter, "render: majorants");
        majorants = std::make_unique<const Majorants>(density, padded, levelSet);
    } else {
        stage(settings.interrupter, "render: shadows");
        shadows = buildShadows(
            {density, padded, *mask, levelSet, sigmaPerVoxel, settings.interrupter, props}, lights,
            settings.shadowCacheVoxels);
    }
    if (interrupted(settings.interrupter)) throw Interrupted();
    const Intersector master(*mask);
    const FrameInputs frame{density,
                            color,
                            lights,
                            medium,
                            levelSet,
                            sigmaPerVoxel,
                            settings.stepVoxels > 0.0 ? settings.stepVoxels : 0.5,
                            padded,
                            master,
                            shadows,
                            majorants.get(),
                            std::max(0, settings.bounces),
                            environment,
                            props};
    stage(settings.interrupter, "render: pixels");
    renderTiles(frame, camera, settings, image);
    stage(settings.interrupter, nullptr);
    if (interrupted(settings.interrupter)) throw Interrupted();
}

} // namespace

Image renderVolume(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                   const Camera& camera, const std::vector<Light>& lights, const Medium& medium,
                   const RenderSettings& settings)
{
    Image image;
    image.width = camera.width();
    image.height = camera.height();
    image.pixels.assign(size_t(image.width) * size_t(image.height) * 4, 0.0f);
    const bool props = settings.props && !settings.props->empty();
    const bool empty = density.tree().activeVoxelCount() == 0;
    if (empty && !props) return image;
    // Props with no volume: the same machinery over one active voxel of the background's value,
    // which adds exactly nothing (its ray-marching structures need an active voxel).
    openvdb::FloatGrid::Ptr nothing;
    if (empty) {
        nothing = density.deepCopy();
        nothing->tree().setValueOn(openvdb::Coord(0), density.background());
    }
    const openvdb::FloatGrid& volume = empty ? *nothing : density;
    auto body = [&] { renderFrame(volume, color, camera, lights, medium, settings, image); };
    if (settings.threads > 0)
        tbb::task_arena(settings.threads).execute(body);
    else
        body();
    return image;
}

} // namespace volmorph::render
