// Random numbers and the phase function: what a sample of the renderer draws and weighs.
#pragma once

#include <volmorph/render/Renderer.h>

#include "Sobol.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace volmorph::render {

/// A sample's random numbers, of two kinds. `next()`: a counter-based generator, for the choices
/// a path makes a varying number of times (tracking, roulette). `nextLD()` / `nextLD2()`: the
/// sample's next dimensions of an Owen-scrambled Sobol sequence (Sobol.h), one per pixel, for the
/// choices every sample makes in the same order (the position in the pixel, the first collision,
/// each vertex's light and direction), so that a pixel's samples stratify them together; after
/// kLowDiscrepancyDims dimensions, the generator. The same (pixel, sample, frame, seed) always
/// gives the same numbers, whichever thread draws them, so frames are bit-identical for any thread
/// count.
struct Random {
    static constexpr uint32_t kLowDiscrepancyDims = 32;
    uint64_t state;
    uint64_t sequence;     ///< the pixel's Sobol sequence (its scrambles' seed)
    uint32_t index;        ///< the sample's index in it
    uint32_t dim = 0;      ///< the next low-discrepancy dimension
    uint32_t shuffled = 0; ///< the sample's index in the current group's shuffle
    Random(uint64_t pixel, uint64_t sample, uint64_t stream)
        : sequence(mix(pixel * 0x9E3779B97F4A7C15ull ^ mix(stream + 0x85157AF5ull))),
          index(uint32_t(sample))
    {
        state = mix(pixel * 0x9E3779B97F4A7C15ull ^ mix(sample + 0x632BE59BD9B4E019ull) ^
                    mix(stream + 0x85157AF5ull));
    }
    static uint64_t mix(uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1), 53 bits.
    double next()
    {
        state += 0x9E3779B97F4A7C15ull;
        return double(mix(state) >> 11) * (1.0 / 9007199254740992.0);
    }
    /// The sample's next low-discrepancy dimension, in [0, 1).
    double nextLD()
    {
        if (dim >= kLowDiscrepancyDims) return next();
        // Every group is entered at its first dimension (nextLD2 skips only odd ones).
        if (dim % 4 == 0) shuffled = sobol::shuffledIndex(index, dim / 4, sequence);
        return sobol::scrambledPoint(shuffled, dim++, sequence);
    }
    /// Two dimensions stratified together (a pair of one group of four).
    void nextLD2(double& u1, double& u2)
    {
        dim += dim & 1u;
        u1 = nextLD();
        u2 = nextLD();
    }
};

/// The unit direction at polar angle acos(cosTheta) and azimuth phi around unit d, in an
/// orthonormal frame around d (Duff et al. 2017).
inline Vec3d directionAround(const Vec3d& d, double cosTheta, double phi)
{
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double sign = std::copysign(1.0, d.z()), a = -1.0 / (sign + d.z()), b = d.x() * d.y() * a;
    const Vec3d e1(1.0 + sign * d.x() * d.x() * a, sign * b, -sign * d.x());
    const Vec3d e2(b, sign + d.y() * d.y() * a, -d.y());
    return (e1 * (sinTheta * std::cos(phi)) + e2 * (sinTheta * std::sin(phi)) + d * cosTheta)
        .unit();
}

/// The direction toward `light` from a point: `center` (towardLight's) for a point light or a
/// directional light of no angle; for a soft sun, a direction drawn uniformly over its disc
/// (light.angle across) when `random` is given.
inline Vec3d sampleLight(const Light& light, const Vec3d& center, Random* random)
{
    if (light.type != Light::Type::Directional || light.angle <= 0.0 || !random) return center;
    const double cosMax = std::cos(0.5 * light.angle);
    double u1, u2;
    random->nextLD2(u1, u2);
    return directionAround(center, 1.0 - u1 * (1.0 - cosMax), 2.0 * M_PI * u2);
}

/// The Henyey-Greenstein phase function (per steradian) at cosTheta between the light's travel and
/// the scattered direction, anisotropy g.
inline double henyeyGreenstein(double cosTheta, double g)
{
    const double d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * d * std::sqrt(d));
}

} // namespace volmorph::render
