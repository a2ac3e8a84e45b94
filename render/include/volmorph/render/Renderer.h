// Volume rendering of a fog density grid: emission-absorption plus single scattering toward
// directional and point lights, with shadows.
//
// Units: extinction is per world unit at density 1, so re-voxelizing a shape does not change how it
// looks; steps are in voxels. Along each ray OpenVDB's VolumeRayIntersector (hierarchical DDA)
// skips empty space, and the ray is sampled at a jittered lattice of step h (one random offset per
// ray, seeded by pixel, sample, frame and seed: no banding, and bit-identical for any thread count).
// Each step of optical depth tau adds T (1 - e^-tau) albedo S and multiplies T by e^-tau (the source
// S held constant over the step); marching stops when T < 1e-4.
//
// Shadows: a transmittance cache per light, computed once per image at every `shadowCacheVoxels`-th
// voxel of the occupied region by marching toward the light with step `shadowStepVoxels`, and
// sampled trilinearly. Its error is the trilinear interpolation of transmittance over the cache
// spacing (smooth fields: second order; at a sharp shadow edge the edge is blurred over that
// spacing). The tests measure it against a closed form.
#pragma once

#include <volmorph/render/Camera.h>

#include <openvdb/openvdb.h>

#include <cstdint>
#include <vector>

namespace volmorph::render {

struct Light {
    enum class Type { Directional, Point };
    Type type = Type::Directional;
    Vec3d direction{0, -1, 0}; ///< directional: the way the light travels (normalized on use)
    Vec3d position{0, 0, 0};   ///< point: world units; irradiance falls off with distance squared
    Vec3d color{1, 1, 1};      ///< linear RGB, times intensity
    double intensity = 1.0;
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
    int samples = 4;               ///< per pixel, stratified and jittered; 1 = through the pixel centre
    double stepVoxels = 0.5;       ///< primary ray step
    double shadowStepVoxels = 1.0; ///< step toward the lights
    int shadowCacheVoxels = 2;     ///< cache spacing, in voxels (1 = every voxel)
    unsigned seed = 0;
    int frame = 0;                 ///< part of the sampling seed
    int threads = 0;               ///< 0 = all cores
};

/// A float RGBA image, RGB premultiplied, linear; A = 1 - transmittance. Row-major, top row first.
struct Image {
    int width = 0, height = 0;
    std::vector<float> pixels; ///< 4 floats per pixel

    float* at(int x, int y) { return &pixels[4 * (size_t(y) * size_t(width) + size_t(x))]; }
    const float* at(int x, int y) const { return &pixels[4 * (size_t(y) * size_t(width) + size_t(x))]; }
};

/// Renders `density` (a fog: any float grid of densities, negative values counting as 0; or a level
/// set, see Medium::Kind), coloured by `color` (linear RGB albedo colour, may be null: white).
Image renderVolume(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color, const Camera& camera,
                   const std::vector<Light>& lights, const Medium& medium, const RenderSettings& settings);

} // namespace volmorph::render
