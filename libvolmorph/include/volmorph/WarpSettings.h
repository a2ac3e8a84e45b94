// The inverse warp's settings (volmorph/Warp.h): its weights and the approximation's error bound.
#pragma once

namespace volmorph {

enum class Weighting { InverseSquare, BeierNeely };

struct WarpSpec {
    double epsilon = 0.01;         ///< world units; w = (d + epsilon)^-2
    double toleranceVoxels = 0.25; ///< approximation error bound; 0 = exact warp
    Weighting weighting = Weighting::InverseSquare;
    /// Beier-Neely weights w = (len^p / (a + d))^b, used only with Weighting::BeierNeely.
    double a = 0.01, b = 2.0, p = 0.0;
};

} // namespace volmorph
