// Density mode: each output voxel's density is (1 - tau) rho_S + tau rho_T of the two sides at
// its warped points (tau: the density schedule at t), its colour the density-weighted mix
// (ColorBlend.h, the colour schedule). Voxels at or below kEmpty stay empty.
#pragma once

#include "blend/BlendMethod.h"

namespace volmorph::detail {

/// Densities at or below this are empty (a trilinear sample at the edge of a fog's support).
inline constexpr float kEmpty = 1e-6f;

std::unique_ptr<const BlendMethod> makeDensityBlend(const BlendSetup& setup);

} // namespace volmorph::detail
