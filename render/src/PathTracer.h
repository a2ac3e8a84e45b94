// One camera ray's radiance by volumetric path tracing: multiple scattering
// (RenderSettings::bounces) and environment light. The unbiased counterpart of RayIntegrator's
// single-scattering estimator.
//
// The camera ray's first collision is sampled exactly, by inverting its optical depth, which the
// cells' closed forms give (Cell.h): a point with density proportional to sigma_t T along the ray,
// given that the ray collides at all, weighted by 1 - T. So the alpha (1 - T, exact, as the single
// scattering estimator's) and the radiance come from one walk, and RGB / A is noise-free where the
// medium's outcome is (a white furnace gives exactly 1). From there the path is traced through the
// volume with delta tracking against the majorant grid (Majorants.h), as pbrt-v4 does: tentative
// collisions at the majorant's rate, each real with probability sigma_t / sigma_majorant.
//
// At every real collision: emission, then the albedo (times the colour grid) scales the path's
// throughput; next-event estimation toward every directional and point light, its transmittance
// by ratio tracking against the same majorants (unbiased: no shadow map is built); then a new
// direction from the Henyey-Greenstein phase function (sampled exactly, so its weight is 1). A path
// that leaves the volume after a collision gathers the environment's radiance. A sky map (Sky.h) is
// also sampled at every collision and prop vertex (a direction drawn from the map, its
// transmittance by ratio tracking), and the two ways of finding its light are weighed by Veach's
// power heuristic against each other: a small bright disc in the map is found as a sun is, and
// a broad sky as the phase function finds it. A camera ray that
// leaves without a collision shows the background, which is transparent (RGB premultiplied, A =
// 1 - T). Collisions are counted like Cycles' volume bounces: `bounces` N allows N + 1 scattering
// events, the last of which still sees the lights and the environment. Russian roulette from the
// third collision on, on the throughput's largest channel.
#pragma once

#include "RayIntegrator.h"
#include "Sampling.h"

namespace volmorph::render {

/// The radiance (linear RGB, premultiplied) and transmittance along one world-space camera ray;
/// `random` is the sample's own stream (Renderer.cpp seeds it per pixel and sample).
RaySample tracePath(ThreadReaders& readers, const Ray& ray, Random& random);

} // namespace volmorph::render
