// How much a map stretches space locally: the spectral norm of its Jacobian.
#pragma once

#include <volmorph/core/Math.h>

#include <algorithm>
#include <cmath>

namespace volmorph::detail {

/// The largest eigenvalue of the symmetric matrix [[a, d, e], [d, b, f], [e, f, c]], in closed
/// form (the trigonometric solution of its characteristic cubic; Smith, 1961). Its rounding is
/// some 1e-15 of the largest eigenvalue, 1e-8 where eigenvalues nearly coincide.
inline double largestSymmetricEigenvalue(double a, double b, double c, double d, double e, double f)
{
    const double offDiagonal = d * d + e * e + f * f;
    if (offDiagonal == 0.0) return std::max({a, b, c});
    const double q = (a + b + c) / 3.0;
    const double p2 = (a - q) * (a - q) + (b - q) * (b - q) + (c - q) * (c - q) + 2.0 * offDiagonal;
    const double p = std::sqrt(p2 / 6.0);
    // B = (A - q I) / p; r = det(B) / 2 lies in [-1, 1] but for rounding.
    const double ba = (a - q) / p, bb = (b - q) / p, bc = (c - q) / p, bd = d / p, be = e / p,
                 bf = f / p;
    const double det =
        ba * (bb * bc - bf * bf) - bd * (bd * bc - bf * be) + be * (bd * bf - bb * be);
    const double r = std::clamp(det / 2.0, -1.0, 1.0);
    return q + 2.0 * p * std::cos(std::acos(r) / 3.0);
}

/// The spectral norm of the matrix with columns dx, dy, dz: the square root of J^T J's largest
/// eigenvalue.
inline double spectralNorm(const Vec3d& dx, const Vec3d& dy, const Vec3d& dz)
{
    const double l = largestSymmetricEigenvalue(dx.dot(dx), dy.dot(dy), dz.dot(dz), dx.dot(dy),
                                                dx.dot(dz), dy.dot(dz));
    return std::sqrt(std::max(l, 0.0));
}

} // namespace volmorph::detail
