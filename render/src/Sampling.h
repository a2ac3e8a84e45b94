// Random numbers and the phase function: what a sample of the renderer draws and weighs.
#pragma once

#include <volmorph/render/Renderer.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace volmorph::render {

/// A counter-based generator: the same (pixel, sample, frame, seed) always gives the same numbers,
/// whichever thread draws them, so frames are bit-identical for any thread count.
struct Random {
    uint64_t state;
    Random(uint64_t a, uint64_t b, uint64_t c)
    {
        state = mix(a * 0x9E3779B97F4A7C15ull ^ mix(b + 0x632BE59BD9B4E019ull) ^
                    mix(c + 0x85157AF5ull));
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
    const double u1 = random->next(), u2 = random->next();
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
