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

/// One sample's part of its pixel: RGBA into `rgba`, the layers (layer::) into `layers` when
/// given, the depth there as the nearest; `viewCosine` is the ray's cosine to the view axis.
void accumulate(const RaySample& sample, double viewCosine, double* rgba, double* layers)
{
    const Vec3d L = sample.L.sum();
    for (int c = 0; c < 3; ++c) rgba[c] += L[c];
    rgba[3] += 1.0 - sample.T;
    if (!layers) return;
    for (int c = 0; c < 3; ++c) {
        layers[layer::kVolume + c] += sample.volumeL[c];
        layers[layer::kDirect + c] += sample.L.direct[c];
        layers[layer::kIndirect + c] += sample.L.indirect[c];
        layers[layer::kEmission + c] += sample.L.emission[c];
    }
    layers[layer::kVolume + 3] += 1.0 - sample.volumeT;
    layers[layer::kShadow] += sample.shadow;
    if (sample.depth != kNoHit)
        layers[layer::kDepth] = std::min(layers[layer::kDepth], sample.depth * viewCosine);
}

/// The pixel (x, y)'s samples averaged into px (RGBA: RGB premultiplied, A = 1 - transmittance)
/// and, when given, `layers` (layer::kFloats).
void renderPixel(ThreadReaders& readers, const Camera& camera, const RenderSettings& settings,
                 int x, int y, float* px, float* layers)
{
    const int samples = std::max(1, settings.samples);
    const int strata = int(std::ceil(std::sqrt(double(samples))));
    double rgba[4] = {0, 0, 0, 0}, sums[layer::kFloats] = {};
    sums[layer::kDepth] = layer::kNoDepth;
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
        accumulate(sample, ray.direction.dot(camera.forward()), rgba, layers ? sums : nullptr);
    }
    for (int c = 0; c < 4; ++c) px[c] = float(rgba[c] / samples);
    if (!layers) return;
    for (int c = 0; c < layer::kFloats; ++c)
        layers[c] = float(c == layer::kDepth ? sums[c] : sums[c] / samples);
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
                                  renderPixel(readers, camera, settings, x, y, image.at(x, y),
                                              image.layers.empty() ? nullptr
                                                                   : image.layersAt(x, y));
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
    const Sky sky = Sky::of(lights);
    // Paths find their transmittance toward the lights by ratio tracking against the majorants;
    // the single-scattering estimator reads shadow maps.
    const bool paths = settings.tracePaths || settings.bounces > 0 || sky.any();
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
                            sky,
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
    if (settings.layers) {
        image.layers.assign(size_t(image.width) * size_t(image.height) * layer::kFloats, 0.0f);
        for (size_t p = 0; p < image.layers.size(); p += layer::kFloats)
            image.layers[p + layer::kDepth] = layer::kNoDepth;
    }
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
