// The renderer's outer levels: what one image prepares (empty-space mask, padded leaves, shadows),
// the loop over tiles, and one pixel's samples. What happens along a ray is RayIntegrator.cpp's.
#include <volmorph/render/Renderer.h>

#include <volmorph/core/Interrupter.h>

#include "Denoiser.h"
#include "Film.h"
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

/// One sample's part of its pixel: RGBA into `rgba`, its RGB into `pass` too, and the layers
/// (layer::, but the depth, which the film keeps) into `layers` when given.
void accumulate(const RaySample& sample, double* rgba, double* pass, double* layers)
{
    const Vec3d L = sample.L.sum();
    for (int c = 0; c < 3; ++c) {
        rgba[c] += L[c];
        pass[c] += L[c];
    }
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
}

/// Pixel (x, y)'s samples from film.count to film.target, added to its sums in their order. Sample
/// s is sample s of the pixel's Sobol sequence: its first two dimensions place it in the pixel (a
/// lone sample goes through the centre, as vdb_render's, unless the settings say otherwise).
void renderPixel(ThreadReaders& readers, const Camera& camera, const RenderSettings& settings,
                 int x, int y, Film& film)
{
    const size_t p = size_t(y) * size_t(film.width()) + size_t(x);
    const uint32_t from = film.count(p), to = film.target(p);
    const bool centre = settings.samples <= 1 && settings.centreSingleSample;
    double* rgba = film.rgba(p);
    double* layers = film.layers(p);
    double pass[3] = {0.0, 0.0, 0.0};
    for (uint32_t s = from; s < to; ++s) {
        Random random(uint64_t(y) * 65536u + uint64_t(x), uint64_t(s),
                      (uint64_t(settings.frame) << 32) ^ settings.seed);
        double sx = 0.5, sy = 0.5;
        random.nextLD2(sx, sy);
        if (centre) sx = sy = 0.5;
        const Ray ray = camera.ray(x + sx, y + sy);
        const RaySample sample = readers.in.majorants ? tracePath(readers, ray, random)
                                                      : integrateRay(readers, ray, &random);
        accumulate(sample, rgba, pass, layers);
        if (sample.depth != kNoHit) // the nearest, camera-space depth
            film.depth(p) =
                std::min(film.depth(p), float(sample.depth * ray.direction.dot(camera.forward())));
    }
    film.finishPass(p, to - from, pass);
}

/// One pass: every pixel whose target is above its count, tiles in parallel. Pixels are
/// independent and each one's samples are seeded by its position, so the result does not depend
/// on how the tiles are scheduled. Throws Interrupted once the interrupter asks (between pixels).
void renderPass(const FrameInputs& frame, const Camera& camera, const RenderSettings& settings,
                Film& film)
{
    tbb::parallel_for(tbb::blocked_range2d<int>(0, film.height(), 16, 0, film.width(), 16),
                      [&](const tbb::blocked_range2d<int>& tile) {
                          ThreadReaders readers(frame);
                          for (int y = tile.rows().begin(); y != tile.rows().end(); ++y)
                              for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
                                  if (interrupted(settings.interrupter)) return;
                                  const size_t p = size_t(y) * size_t(film.width()) + size_t(x);
                                  if (film.target(p) > film.count(p))
                                      renderPixel(readers, camera, settings, x, y, film);
                              }
                      });
    if (interrupted(settings.interrupter)) throw Interrupted();
}

/// Every pixel's target set to `samples`.
void targetAll(Film& film, uint32_t samples)
{
    for (size_t p = 0; p < film.pixels(); ++p) film.target(p) = samples;
}

/// The pixels whose estimated error (`error`, smoothed) exceeds the frame's per-pixel share of the
/// target's (all pixels' mean variance at the noise target), each set to twice its samples, up to
/// `cap`; when none does while the frame is still above the target, a lower share. False when no
/// pixel can take more samples.
bool chooseNextPass(Film& film, const std::vector<double>& error, double target, uint32_t cap)
{
    const double mean = film.coveredMean();
    for (double share = (target * mean) * (target * mean); share > 0.0; share *= 0.25) {
        bool any = false;
        for (size_t p = 0; p < film.pixels(); ++p) {
            const uint32_t n = film.count(p);
            const bool more = n < cap && error[p] > share;
            film.target(p) = more ? std::min<uint32_t>(cap, 2 * n) : n;
            any = any || more;
        }
        if (any) return true;
        if (share < 1e-12 * mean * mean) break;
    }
    return false;
}

/// The image's passes: with no noise target, exactly `samples` samples per pixel in two halves
/// (the second half's difference from the first is the noise estimate); with one, the first
/// kFirstSamples in two halves, then passes that double the samples of the pixels still noisy
/// (chooseNextPass) until the frame's estimated noise, denoised unless the settings say not to,
/// reaches the target or no pixel may take more.
Image renderPasses(const FrameInputs& frame, const Camera& camera, const RenderSettings& settings,
                   Film& film)
{
    constexpr uint32_t kFirstSamples = 16;
    const uint32_t cap = uint32_t(std::max(1, settings.samples));
    const uint32_t first = settings.noise > 0.0 ? std::min(cap, kFirstSamples) : cap;
    if (first >= 2) {
        targetAll(film, first / 2);
        renderPass(frame, camera, settings, film);
    }
    targetAll(film, first);
    renderPass(frame, camera, settings, film);
    if (!(settings.noise > 0.0)) return film.resolve();
    for (;;) {
        Image image = film.resolve();
        std::vector<double> error;
        if (settings.denoise) {
            stage(settings.interrupter, "render: denoise");
            error = boxMean3(denoise(film, film.depths(), image, settings.interrupter).variance,
                             film.width(), film.height());
        } else {
            error = smoothedVariance(film);
        }
        if (!(image.noise > settings.noise) || !chooseNextPass(film, error, settings.noise, cap))
            return image;
        stage(settings.interrupter, "render: pixels");
        renderPass(frame, camera, settings, film);
    }
}

/// Prepares what every ray reads (the empty-space mask, padded leaves, every light's shadow), then
/// renders the tiles. Throws Interrupted when the interrupter asked to stop.
void renderFrame(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                 const Camera& camera, const std::vector<Light>& lights, const Medium& medium,
                 const RenderSettings& settings, Film& film, Image& image)
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
    image = renderPasses(frame, camera, settings, film);
    stage(settings.interrupter, nullptr);
}

} // namespace

Image renderVolume(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                   const Camera& camera, const std::vector<Light>& lights, const Medium& medium,
                   const RenderSettings& settings)
{
    const bool props = settings.props && !settings.props->empty();
    const bool empty = density.tree().activeVoxelCount() == 0;
    Film film(camera.width(), camera.height(), settings.layers);
    if (empty && !props) return film.resolve();
    // Props with no volume: the same machinery over one active voxel of the background's value,
    // which adds exactly nothing (its ray-marching structures need an active voxel).
    openvdb::FloatGrid::Ptr nothing;
    if (empty) {
        nothing = density.deepCopy();
        nothing->tree().setValueOn(openvdb::Coord(0), density.background());
    }
    const openvdb::FloatGrid& volume = empty ? *nothing : density;
    Image image;
    auto body = [&] { renderFrame(volume, color, camera, lights, medium, settings, film, image); };
    if (settings.threads > 0)
        tbb::task_arena(settings.threads).execute(body);
    else
        body();
    return image;
}

} // namespace volmorph::render
