// Random numbers and the phase function: what a sample of the renderer draws and weighs.
#pragma once

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

/// The Henyey-Greenstein phase function (per steradian) at cosTheta between the light's travel and
/// the scattered direction, anisotropy g.
inline double henyeyGreenstein(double cosTheta, double g)
{
    const double d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * d * std::sqrt(d));
}

} // namespace volmorph::render
