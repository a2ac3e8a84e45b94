// One interpolation cell of a density grid and the exact optical depth of a ray piece through it.
//
// A cell is the cube [c, c + 1]^3 between eight voxel centres (index space), where OpenVDB's
// BoxSampler is trilinear. Along a ray the trilinear density is a cubic polynomial of the distance,
// so the integral of density over a piece of the ray inside one cell has a closed form (Piece).
// Ray times here are in voxels: the index-space ray has unit speed.
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>

namespace volmorph::render {

/// Transmittance below this ends a ray: what is behind contributes less than 1e-4.
constexpr double kMinTransmittance = 1e-4;
inline const double kMaxOpticalDepth = -std::log(kMinTransmittance);

/// The eight values at the corners of one interpolation cell [c, c + 1]^3 (voxel centres sit at
/// integer index coordinates) and OpenVDB's trilinear interpolant inside it (BoxSampler's).
struct Cell {
    float v[2][2][2];
    openvdb::Coord origin;
    float lo, hi;       ///< smallest and largest corner value
    bool block = false; ///< one constant value over a whole block crossing (see walkCells)

    __attribute__((always_inline)) double
    at(const Vec3d& u) const // u: local coordinates in [0, 1]^3
    {
        const double x = u.x(), y = u.y(), z = u.z();
        const double a = v[0][0][0] + (v[0][0][1] - v[0][0][0]) * z;
        const double b = v[0][1][0] + (v[0][1][1] - v[0][1][0]) * z;
        const double c = v[1][0][0] + (v[1][0][1] - v[1][0][0]) * z;
        const double d = v[1][1][0] + (v[1][1][1] - v[1][1][0]) * z;
        const double e = a + (b - a) * y;
        const double f = c + (d - c) * y;
        return e + (f - e) * x;
    }
};

/// An index-space ray and the optical "mass" of a medium along it: the integral of density over a
/// piece [ta, tb] of the ray inside one cell, in voxels times density.
struct Medium1D {
    Vec3d eye, dir; ///< index space; dir has unit length, so ray times are in voxels
    bool levelSet;

    /// The integral of the density along [ta, tb] within `cell`. For a fog whose corners are all
    /// non-negative the trilinear interpolant is a cubic polynomial along the ray, integrated in
    /// closed form (Piece). A level set's density is 1 where the
    /// interpolated distance is negative: the length of that part, with each zero crossing placed
    /// by linear interpolation between the ends and the midpoint. A fog with negative corners
    /// (negative densities count as 0): the clamped value at four midpoints.
    inline double mass(const Cell& cell, double ta, double tb) const;
};

/// The density along one piece of a ray inside one cell, as a polynomial in s = t - ta (voxels),
/// for a fog whose corners are non-negative: the trilinear interpolant restricted to a line is a
/// cubic. mass(s) is its integral over [0, s]; exact is false for other cells (use Medium1D::mass).
struct Piece {
    bool exact = false;
    double c[4] = {0, 0, 0, 0};

    Piece(const Medium1D& ray, const Cell& cell, double ta)
    {
        if (ray.levelSet || cell.lo < 0.0f) return;
        exact = true;
        const Vec3d u =
            ray.eye + ray.dir * ta - Vec3d(cell.origin.x(), cell.origin.y(), cell.origin.z());
        const Vec3d& d = ray.dir;
        // Weights of the corners 0 and 1 along each axis, as linear functions w0 + w1 s.
        const double z[2][2] = {{1.0 - u.z(), -d.z()}, {u.z(), d.z()}};
        const double y[2][2] = {{1.0 - u.y(), -d.y()}, {u.y(), d.y()}};
        const double x[2][2] = {{1.0 - u.x(), -d.x()}, {u.x(), d.x()}};
        double h[2][3]; // along z, then y: a quadratic per x corner
        for (int i = 0; i < 2; ++i) {
            h[i][0] = h[i][1] = h[i][2] = 0.0;
            for (int j = 0; j < 2; ++j) {
                const double g0 = cell.v[i][j][0] * z[0][0] + cell.v[i][j][1] * z[1][0];
                const double g1 = cell.v[i][j][0] * z[0][1] + cell.v[i][j][1] * z[1][1];
                h[i][0] += g0 * y[j][0];
                h[i][1] += g0 * y[j][1] + g1 * y[j][0];
                h[i][2] += g1 * y[j][1];
            }
        }
        for (int i = 0; i < 2; ++i) {
            c[0] += h[i][0] * x[i][0];
            c[1] += h[i][0] * x[i][1] + h[i][1] * x[i][0];
            c[2] += h[i][1] * x[i][1] + h[i][2] * x[i][0];
            c[3] += h[i][2] * x[i][1];
        }
    }

    double mass(double s) const
    {
        return s * (c[0] + s * (0.5 * c[1] + s * (c[2] * (1.0 / 3.0) + s * 0.25 * c[3])));
    }
};

double Medium1D::mass(const Cell& cell, double ta, double tb) const
{
    const double length = tb - ta;
    const Vec3d base = eye - Vec3d(cell.origin.x(), cell.origin.y(), cell.origin.z());
    auto local = [&](double t) { return base + dir * t; };
    if (!levelSet) {
        if (cell.hi <= 0.0f) return 0.0;
        if (cell.lo >= 0.0f) return Piece(*this, cell, ta).mass(length);
        double sum = 0.0;
        for (int k = 0; k < 4; ++k)
            sum += std::max(0.0, cell.at(local(ta + (k + 0.5) * 0.25 * length)));
        return 0.25 * length * sum;
    }
    if (cell.lo >= 0.0f) return 0.0;
    if (cell.hi < 0.0f) return length;
    const double f0 = cell.at(local(ta)), f1 = cell.at(local(0.5 * (ta + tb))),
                 f2 = cell.at(local(tb));
    auto inside = [](double a, double b,
                     double h) { // length of the negative part of a linear piece
        if (a < 0.0 && b < 0.0) return h;
        if (a >= 0.0 && b >= 0.0) return 0.0;
        const double crossing = a / (a - b) * h; // from the start
        return a < 0.0 ? crossing : h - crossing;
    };
    return inside(f0, f1, 0.5 * length) + inside(f1, f2, 0.5 * length);
}

/// e^-x for x >= 0; a short series where x is small (the common case of one step of a thin medium,
/// relative error below 1e-10 for x < 0.05).
inline double expNegative(double x)
{
    constexpr double third = 1.0 / 3.0, sixth = 1.0 / 6.0;
    if (x < 0.05)
        return 1.0 -
               x * (1.0 -
                    x * 0.5 *
                        (1.0 - x * third * (1.0 - x * 0.25 * (1.0 - x * 0.2 * (1.0 - x * sixth)))));
    return std::exp(-x);
}

} // namespace volmorph::render
