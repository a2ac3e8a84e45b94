// variational mode (blend.mode = "variational"): Turk and O'Brien's variational implicit morph
// ("Shape Transformation Using Variational Implicit Functions", SIGGRAPH 1999). The source's
// constraints are placed at t = 0 and the target's at t = 1 (and each influence shape's at its t)
// in four dimensions, (x, y, z, t * time_scale); the smoothest function through them, r^3 with a
// linear polynomial (variational/Interpolant.h), is solved once per morph by a two-level
// partition of unity (variational/PartitionOfUnity.h), and each in-between is its zero set in the
// slice at t. No correspondence: the feature pairs are not used.
//
// A frame evaluates the function on lattices from coarse to fine near its zero set only
// (variational/Slice.h: the domain is found from the function, so an in-between away from both
// shapes is found too), rebuilds the band as distances (Redistance.h) and derives the fog; `Cd` is
// each side's colour at its nearest surface point (through each side's extended distance,
// ExtendedDistance.h: p - d grad d), mixed by the colour schedule; `vel` is the zero set's normal
// motion, -f_t grad f / |grad f|^2, on the band (the interior has none: its fog does not move).
// The carried grids of volume inputs (blend.grids) are not blended in this mode.
//
// Under a timing (LocalTime.h) each place takes the function at its own local time: the in-between
// is the zero set of g(x) = f(x, tau(x, t) * time_scale), one closed surface as a slice is (g is
// continuous and positive far from the shapes), and its motion -g_t grad g / |grad g|^2 takes grad
// tau in through grad g.
#pragma once

#include "blend/BlendMethod.h"

namespace volmorph::detail {

/// Throws UserError (at [variational]) when the constraints' solve would need more than the
/// memory limit, before it starts.
std::unique_ptr<const BlendMethod> makeVariationalBlend(const BlendSetup& setup);

} // namespace volmorph::detail
