// Volume rendering of a fog density grid: emission-absorption plus single scattering toward
// directional and point lights, with shadows.
//
// Units: extinction is per world unit at density 1, so re-voxelizing a shape does not change how it
// looks; steps are in voxels (index units). Along each ray OpenVDB's VolumeRayIntersector
// (hierarchical DDA) skips empty space; inside the occupied spans a 3D DDA visits every
// interpolation cell the ray crosses (the cube between eight voxel centres, where OpenVDB's
// BoxSampler is trilinear). Along one cell the density is a cubic polynomial of the distance, so
// its optical depth is integrated exactly: alpha has no step error, no sample lattice and so no
// banding, whatever the step. Cells inside an 8^3 block of one value (a tile, or a leaf whose
// values are all equal) are crossed as one piece.
// Each piece is cut into equal steps of at most `stepVoxels`; each step adds T (1 - e^-tau) S at
// its middle and multiplies T by e^-tau, tau being the step's exact optical depth. The source S
// (emission plus albedo times the light reaching the point) is evaluated at knots along the ray,
// the first step end at least one voxel after the previous knot (so knots are 1 to 1 + step voxels
// apart), and taken linearly in between. That is the only approximation along the ray: second
// order in the knot spacing, on a quantity that the shadow lookup already smooths over
// `shadowCacheVoxels`. Marching stops when T < 1e-4.
//
// Shadows: for a directional light, a deep shadow map (Lokovic and Veach 2000): columns parallel to
// the light every `shadowCacheVoxels` voxels, each integrated exactly cell by cell through the
// volume once per image, keeping the transmittance every `shadowCacheVoxels` along it, and looked
// up with trilinear interpolation in the light's frame. For a point light, the same with rays
// leaving the light through a cube map's lattice, at most that spacing apart across the occupied
// region, sampled every `shadowCacheVoxels` of distance from the light. Each ray keeps the fewest
// knots whose linear interpolation is within 2.5e-4 of its steps' transmittance (Lokovic and
// Veach's compression): a few dozen at any voxel size, so the maps grow with the region's
// cross-section, not its volume. The error of both is the interpolation of transmittance over that
// spacing (smooth fields: second order; a sharp shadow edge is blurred over the spacing) plus that
// 2.5e-4; the tests measure it against the exact march and a closed form.
//
// Sampling: one ray through each pixel centre for samples = 1; otherwise each pixel's samples are
// the points of an Owen-scrambled Sobol sequence of its own (its position in the pixel, the first
// collision, each vertex's light and direction), seeded by pixel, frame and seed. With a noise
// target (RenderSettings::noise) the samples come in passes that double the noisy pixels'; the
// decisions are taken between passes from the whole frame. Nothing depends on the thread count,
// so images are bit-identical for any --threads.
#pragma once

#include <volmorph/render/Camera.h>
#include <volmorph/render/Props.h>

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace volmorph::render {

class EnvironmentMap;

/// Units as Cycles': a directional light's color x intensity is the irradiance on a surface facing
/// it (sun strength); a point light's is its intensity (irradiance times distance squared); an
/// environment's is the radiance arriving from every direction (background strength).
struct Light {
    enum class Type { Directional, Point, Environment };
    Type type = Type::Directional;
    Vec3d direction{0, -1, 0}; ///< directional: the way the light travels (normalized on use)
    Vec3d position{0, 0, 0};   ///< point: world units; irradiance falls off with distance squared
    Vec3d color{1, 1, 1};      ///< linear RGB, times intensity
    double intensity = 1.0;
    /// Directional: the angular diameter of the disc it comes from (radians; 0: a point at
    /// infinity). Its irradiance stays color x intensity. Surfaces and paths sample the disc; the
    /// single-scattering estimator's shadow map inside the volume keeps its centre direction.
    double angle = 0.0;
    /// Environment: a lat-long HDR map (EnvironmentMap.h) whose radiance, times color x intensity,
    /// arrives from each direction, importance-sampled; null: color x intensity from every one.
    /// At most one environment light of an image has a map.
    std::shared_ptr<const EnvironmentMap> map;
};

struct Medium {
    /// Fog: the grid holds densities. LevelSet: the grid is a signed distance field (world units,
    /// negative inside) and the density is 1 where it is negative: a homogeneous body with a sharp
    /// surface at the zero crossing of the trilinearly interpolated distance.
    enum class Kind { Fog, LevelSet };
    Kind kind = Kind::Fog;
    double extinction = 40.0; ///< per world unit at density 1
    double albedo = 0.8;      ///< scattering / extinction
    double anisotropy = 0.0;  ///< Henyey-Greenstein g
    Vec3d emission{0, 0, 0};  ///< radiance emitted per unit optical depth, linear RGB
};

struct RenderSettings {
    /// Per pixel: exactly this many with no noise target, at most this many with one; 1 = through
    /// the pixel centre.
    int samples = 4;
    /// The noise target: the frame's relative RMSE against its converged image (over the pixels
    /// with alpha above 0.1, relative to their mean RGB), which the renderer estimates from the two
    /// halves of each pixel's samples and stops at, doubling the samples of the pixels still
    /// noisy, up to `samples`. 0: exactly `samples` samples everywhere (the reference mode).
    double noise = 0.0;
    /// Under a noise target: the frame denoised (non-local means guided by alpha and depth, the
    /// radiance layers alike), and the target judged on the denoised frame's estimate. Trades a
    /// little bias (BENCHMARKS.md measures it) for much less noise. Ignored at noise 0.
    bool denoise = true;
    double stepVoxels = 0.5; ///< longest step of the scattering integral along a primary ray
    /// The single-scattering estimator's shadow maps' spacing, in voxels (1 =
    /// every voxel); 0: no cache, the exact transmittance toward each light marched per sample (the
    /// reference the caches are judged by). Traced paths need none: they estimate the
    /// transmittance toward lights by ratio tracking, without bias.
    /// 1 by default: at 2 a lit surface came out 6% too bright against Cycles and exact marching,
    /// with voxel-aligned striations; at 1 it is within 1% for a 16-bounce frame, for the same
    /// time at 125 voxels across (BENCHMARKS.md, "The look, part 1").
    int shadowCacheVoxels = 1;
    /// Scattering events after the first, as Cycles' volume bounces. 0 with no environment light:
    /// the single-scattering estimator above. Otherwise each sample traces a path (PathTracer.h in
    /// render/src: null-scattering path tracing against a majorant grid); the alpha is the same
    /// exact 1 - T either way.
    int bounces = 0;
    bool tracePaths = false; ///< trace paths also for bounces 0 without environment (comparisons)
    unsigned seed = 0;
    int frame = 0; ///< part of the sampling seed
    /// samples = 1 goes through the pixel centre unless this is false (then jittered over the
    /// pixel, as each shutter time's one sample is).
    bool centreSingleSample = true;
    int threads = 0; ///< 0 = all cores
    /// Meshes in the shot (Props.h), built once for a sequence; null: none.
    const Props* props = nullptr;
    /// Fill Image::layers (the layers for compositing) besides RGBA.
    bool layers = false;
    /// Asked between pixels and between the shadow maps' columns (OpenVDB's interrupter interface);
    /// when it answers true, renderVolume throws volmorph::Interrupted. May be null.
    openvdb::util::NullInterrupter* interrupter = nullptr;
};

/// The layers for compositing beside RGBA (RenderSettings::layers), as floats per pixel at these
/// offsets:
/// - Volume (RGBA): the volume alone, in front of the first prop: RGB premultiplied, A = 1 - its
///   transmittance.
/// - Direct, Indirect, Emission (RGB each): the beauty's RGB split three ways (they add up to it):
///   light arriving at the path's first vertex (a collision in the volume, or the prop the camera
///   sees) from a light or the environment with no scattering between; light that scattered at
///   least once more; the medium's emission at the first vertex (single scattering: along the ray).
/// - Shadow (A): a shadow catcher's matte times the volume's transmittance in front of it, its
/// share
///   of the alpha: A = volume.A + shadow where a catcher is behind, volume.A elsewhere.
/// - Depth (Z): camera-space depth (world units along the view axis) of the first point where the
///   volume's alpha passes 0.5, or of the first prop if it comes before; the nearest over the
///   pixel's samples; kNoDepth where neither (as Cycles' 1e10).
namespace layer {
inline constexpr int kVolume = 0, kDirect = 4, kIndirect = 7, kEmission = 10, kShadow = 13,
                     kDepth = 14, kFloats = 15;
inline constexpr float kNoDepth = 1e10f;
} // namespace layer

/// A float RGBA image, RGB premultiplied, linear; A = 1 - transmittance. Row-major, top row first.
struct Image {
    int width = 0, height = 0;
    std::vector<float> pixels; ///< 4 floats per pixel
    std::vector<float> layers; ///< empty, or layer::kFloats floats per pixel (see layer::)
    /// Per pixel, the estimated variance of its RGB (the mean over the channels of the variance of
    /// each channel's estimate), from the two halves of its samples; empty or 0 where not
    /// estimated (one sample).
    std::vector<float> variance;
    /// The frame's estimated relative noise (estimateNoise in the renderer: the RMS of the pixels'
    /// estimated errors over the pixels it covers, over their mean); NaN when not estimated.
    double noise = std::numeric_limits<double>::quiet_NaN();
    double meanSamples = 0.0; ///< the samples a pixel took, on average (times summed under blur)

    float* at(int x, int y) { return &pixels[4 * index(x, y)]; }
    const float* at(int x, int y) const { return &pixels[4 * index(x, y)]; }
    float* layersAt(int x, int y) { return &layers[size_t(layer::kFloats) * index(x, y)]; }
    const float* layersAt(int x, int y) const
    {
        return &layers[size_t(layer::kFloats) * index(x, y)];
    }
    size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};

/// The pixels a noise figure is taken over: those whose alpha exceeds this (as the benchmarks'
/// image comparisons).
inline constexpr double kNoiseMinAlpha = 0.1;

/// The image's relative noise: the root mean square of its pixels' estimated error (the square
/// root of Image::variance) over the pixels it covers (alpha > kNoiseMinAlpha), divided by their
/// mean RGB. NaN when it has no variance (one sample per pixel) or covers nothing.
double estimateNoise(const Image& image);

/// Renders `density` (a fog: any float grid of densities, negative values counting as 0; or a level
/// set, see Medium::Kind), coloured by `color` (linear RGB albedo colour, may be null: white).
/// Throws volmorph::Interrupted (volmorph/core/Interrupter.h) when settings.interrupter asks to
/// stop.
Image renderVolume(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                   const Camera& camera, const std::vector<Light>& lights, const Medium& medium,
                   const RenderSettings& settings);

/// One time in the shutter: seconds from the frame (negative before it), and the camera and lights
/// at that time (keyed ones move, and blur).
struct ShutterTime {
    double seconds = 0.0;
    Camera camera;
    std::vector<Light> lights;
};

/// The shutter's times for `samples` samples per pixel, in frames from the frame: one per sample,
/// up to 64, evenly spread over [open, close] (each at the middle of its share).
std::vector<double> shutterOffsets(double open, double close, int samples);

/// The seed renderMotionBlurred renders shutter time k (from 0) with, from the settings' seed: the
/// times' samples lie apart.
inline unsigned shutterSeed(unsigned seed, size_t k)
{
    return seed ^ unsigned(0x9E3779B9u * (k + 1));
}

/// Eulerian motion blur: the mean of one image per time in `times`, each of the density (and
/// colour) advected along `velocity` (world units per second; null or all zero: the volume stands
/// still and only the cameras and lights move) by its seconds, rho(p - v(p) s): moved by the
/// density-weighted mean velocity exactly (the grids' transforms) and by the rest through
/// OpenVDB's semi-Lagrangian VolumeAdvection; seen by its camera under its lights, with
/// samples / times.size() samples per pixel (at least 1; set centreSingleSample false to jitter a
/// lone one), seeded apart (shutterSeed). Props with vertex velocities (PropMesh::velocities) are
/// built again at each time, each vertex moved linearly. Exact for a translation, without
/// resampling;
/// `velocity` must cover where the density arrives within the times (volmorph's vel does:
/// MorphOptions::velocityReachSeconds).
Image renderMotionBlurred(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                          const openvdb::Vec3SGrid* velocity, const std::vector<ShutterTime>& times,
                          const Medium& medium, const RenderSettings& settings);

} // namespace volmorph::render
