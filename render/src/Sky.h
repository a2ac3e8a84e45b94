// The environment lights of one image, summed: a constant radiance from every direction, and at
// most one lat-long map (EnvironmentMap.h) times its light's colour and intensity.
#pragma once

#include <volmorph/render/EnvironmentMap.h>
#include <volmorph/render/Renderer.h>

#include <stdexcept>
#include <vector>

namespace volmorph::render {

struct Sky {
    Vec3d constant{0.0};                 ///< the constant environments' radiance, summed
    const EnvironmentMap* map = nullptr; ///< null: none
    Vec3d mapScale{0.0};                 ///< the map light's color x intensity

    bool any() const { return constant != Vec3d(0.0) || map; }

    /// The map's part of the radiance arriving from unit world direction w.
    Vec3d mapRadiance(const Vec3d& w) const { return map->radiance(w) * mapScale; }

    /// The environment lights among `lights`; throws std::invalid_argument for two maps.
    static Sky of(const std::vector<Light>& lights)
    {
        Sky sky;
        for (const Light& light : lights) {
            if (light.type != Light::Type::Environment) continue;
            if (!light.map) {
                sky.constant += light.color * light.intensity;
                continue;
            }
            if (sky.map) throw std::invalid_argument("at most one environment light has a map");
            sky.map = light.map.get();
            sky.mapScale = light.color * light.intensity;
        }
        return sky;
    }
};

/// Veach's power heuristic: the weight of a sample drawn with density a when b could have drawn
/// it too.
inline double powerHeuristic(double a, double b)
{
    return a * a / (a * a + b * b);
}

} // namespace volmorph::render
