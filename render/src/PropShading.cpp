#include "PropShading.h"

#include "Shadows.h"

#include <algorithm>
#include <cmath>

namespace volmorph::render {

Vec3d directIrradiance(ThreadReaders& readers, const Vec3d& x, const Vec3d& n, Vec3d& unoccluded,
                       Random* random)
{
    const FrameInputs& in = readers.in;
    Vec3d received(0.0);
    unoccluded = Vec3d(0.0);
    for (const Light& light : in.lights) {
        if (light.type == Light::Type::Environment) continue;
        double distance;
        const Vec3d toward = sampleLight(light, towardLight(light, x, distance), random);
        const double cosine = n.dot(toward);
        if (cosine <= 0.0) continue;
        const double falloff = light.type == Light::Type::Point ? 1.0 / (distance * distance) : 1.0;
        const Vec3d E = light.color * (light.intensity * falloff * cosine);
        unoccluded += E;
        received += E * exactVisibility(readers, x, toward, distance);
    }
    return received;
}

double shadowMatte(const Vec3d& received, const Vec3d& unoccluded)
{
    const double reference = unoccluded.x() + unoccluded.y() + unoccluded.z();
    if (reference <= 0.0) return 0.0;
    const double seen = received.x() + received.y() + received.z();
    return std::clamp(1.0 - seen / reference, 0.0, 1.0);
}

void finishOnProp(const PropMesh& prop, double distance, const Radiance& surface, double matte,
                  RaySample& out)
{
    out.depth = std::min(out.depth, distance);
    switch (prop.role) {
    case PropMesh::Role::Diffuse:
        if (prop.subject) {
            out.volumeL += surface.sum() * out.T;
            out.volumeT = 0.0;
        }
        out.L.direct += surface.direct * out.T;
        out.L.indirect += surface.indirect * out.T;
        out.L.emission += surface.emission * out.T;
        out.T = 0.0;
        break;
    case PropMesh::Role::Holdout:
        break;
    case PropMesh::Role::ShadowCatcher:
        out.shadow = matte * out.T;
        out.T *= 1.0 - matte;
        break;
    }
}

Vec3d surfacePoint(const Ray& ray, const PropHit& hit)
{
    const Vec3d x = ray.origin + ray.direction * hit.distance;
    const double scale = std::max({1.0, std::abs(x.x()), std::abs(x.y()), std::abs(x.z())});
    return x + hit.normal * (1e-5 * scale);
}

} // namespace volmorph::render
