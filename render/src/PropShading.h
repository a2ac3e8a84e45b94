// What a camera ray or a path finds on a prop (Props.h): the direct light on a diffuse surface
// (through the props' occlusion and the volume's exact transmittance toward each light), and what
// each role does to the pixel.
#pragma once

#include <volmorph/render/Props.h>

#include "RayIntegrator.h"
#include "Sampling.h"

namespace volmorph::render {

/// The direct light on a surface at world point x with unit normal n (facing the arriving ray)
/// from every directional and point light: sum of E cos(theta) times the props' visibility times
/// the volume's transmittance (exact, cell by cell), where E is the light's irradiance on a
/// surface facing it. `unoccluded` gets the same sum without visibility and transmittance (a
/// shadow catcher's reference). A soft sun's direction is drawn over its disc with `random` (its
/// centre without).
Vec3d directIrradiance(ThreadReaders& readers, const Vec3d& x, const Vec3d& n, Vec3d& unoccluded,
                       Random* random);

/// The radiance a diffuse surface of reflectance `color` sends back under `irradiance`: color / pi
/// times it.
inline Vec3d diffuseRadiance(const Vec3d& color, const Vec3d& irradiance)
{
    constexpr double kInvPi = 0.31830988618379067;
    return Vec3d(color.x() * irradiance.x(), color.y() * irradiance.y(),
                 color.z() * irradiance.z()) *
           kInvPi;
}

/// A shadow catcher's matte: 1 - received / unoccluded (per channel's mean), 0 without light.
double shadowMatte(const Vec3d& received, const Vec3d& unoccluded);

/// A camera ray that reached prop `hit`, `distance` world units along it, with `out` the volume in
/// front of it (radiance, and its transmittance T): a diffuse prop adds T times `surface` (its
/// radiance) and makes the pixel opaque; a holdout keeps the alpha of the volume in front only; a
/// shadow catcher adds no colour and `matte` times T to the alpha (out.shadow). A subject prop
/// (PropMesh::subject) goes into the volume's layer too (volumeL, volumeT). The depth becomes
/// the prop's unless the volume's alpha passed 0.5 before it.
void finishOnProp(const PropMesh& prop, double distance, const Radiance& surface, double matte,
                  RaySample& out);

/// The world point a camera ray meets its prop at, nudged off the surface along its normal.
Vec3d surfacePoint(const Ray& ray, const PropHit& hit);

} // namespace volmorph::render
