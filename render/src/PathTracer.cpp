#include "PathTracer.h"

#include "Cell.h"
#include "CellWalk.h"
#include "Majorants.h"

#include <algorithm>
#include <cmath>

namespace volmorph::render {
namespace {

/// A direction drawn from the Henyey-Greenstein phase function around the travel direction `d`
/// (unit): cos(d, result) has density proportional to HG(g), by inverting its distribution.
Vec3d sampleHenyeyGreenstein(const Vec3d& d, double g, double u1, double u2)
{
    double cosTheta;
    if (std::abs(g) < 1e-3) {
        cosTheta = 1.0 - 2.0 * u1;
    } else {
        const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        cosTheta = std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
    }
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double phi = 2.0 * M_PI * u2;
    // An orthonormal frame around d (Duff et al. 2017).
    const double sign = std::copysign(1.0, d.z()), a = -1.0 / (sign + d.z()), b = d.x() * d.y() * a;
    const Vec3d e1(1.0 + sign * d.x() * d.x() * a, sign * b, -sign * d.x());
    const Vec3d e2(b, sign + d.y() * d.y() * a, -d.y());
    return (e1 * (sinTheta * std::cos(phi)) + e2 * (sinTheta * std::sin(phi)) + d * cosTheta)
        .unit();
}

/// The camera ray's walk, piece by piece, with the optical depth before each piece, until the ray
/// leaves the volume or its transmittance drops below kMinTransmittance (where the single
/// scattering estimator stops too). Returns the total optical depth.
double walkPrimary(ThreadReaders& r, const Medium1D& line)
{
    const FrameInputs& in = r.in;
    r.pieces.clear();
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    auto visit = [&](const Cell& cell, double ta, double tb) {
        const double rho = in.levelSet ? 1.0 : double(cell.hi);
        const double piece =
            in.sigmaPerVoxel * (cell.block ? rho * (tb - ta) : line.mass(cell, ta, tb));
        r.pieces.push_back(TracedPiece{cell, ta, tb, tau});
        tau += piece;
        return tau < kMaxOpticalDepth;
    };
    while (r.inter.march(t0, t1) && walkCells(r.density, line, t0, t1, visit)) {}
    return tau;
}

/// The ray time (voxels) at which the camera ray's optical depth reaches `target` (< the total).
double invertPrimary(const ThreadReaders& r, const Medium1D& line, double target)
{
    const auto& pieces = r.pieces;
    // The last piece starting at or before the target.
    auto it = std::upper_bound(pieces.begin(), pieces.end(), target,
                               [](double v, const TracedPiece& p) { return v < p.tauBefore; });
    const TracedPiece& p = *std::prev(it == pieces.begin() ? std::next(it) : it);
    const double want = (target - p.tauBefore) / r.in.sigmaPerVoxel, length = p.tb - p.ta;
    if (p.cell.block) {
        const double rho = r.in.levelSet ? 1.0 : double(p.cell.hi);
        return p.ta + std::clamp(want / rho, 0.0, length);
    }
    const Piece poly(line, p.cell, p.ta);
    auto mass = [&](double s) {
        return poly.exact ? poly.mass(s) : line.mass(p.cell, p.ta, p.ta + s);
    };
    double lo = 0.0, hi = length; // the mass is non-decreasing in s: bisection
    for (int i = 0; i < 48 && hi - lo > 1e-9; ++i) {
        const double mid = 0.5 * (lo + hi);
        (mass(mid) < want ? lo : hi) = mid;
    }
    return p.ta + 0.5 * (lo + hi);
}

/// One path from the camera ray's first collision on: its radiance.
class Path {
public:
    Path(ThreadReaders& readers, Random& random) : mR(readers), mIn(readers.in), mRandom(random) {}

    /// The radiance of the path that collides first at index point ip, travelling along `dir`.
    Vec3d trace(Vec3d ip, Vec3d dir)
    {
        Vec3d L(0.0), beta(1.0);
        for (int vertex = 0;; ++vertex) {
            L += beta * mIn.medium.emission;
            beta = beta * albedoAt(ip);
            if (beta.x() <= 0.0 && beta.y() <= 0.0 && beta.z() <= 0.0) break;
            L += beta * directLight(ip, dir);
            if (vertex == mIn.bounces && mIn.environment == Vec3d(0.0)) break;
            if (vertex >= 2 && !survives(beta)) break;
            dir =
                sampleHenyeyGreenstein(dir, mIn.medium.anisotropy, mRandom.next(), mRandom.next());
            if (!track(ip, dir)) {
                L += beta * mIn.environment;
                break;
            }
            if (vertex == mIn.bounces) break;
        }
        return L;
    }

private:
    Vec3d albedoAt(const Vec3d& ip)
    {
        if (mR.colors) return mR.colors->at(ip) * mIn.medium.albedo;
        return Vec3d(mIn.medium.albedo);
    }

    /// Next-event estimation: every directional and point light's radiance scattered at ip toward
    /// -dir, through the medium's transmittance toward the light (ratio tracking: no shadow map,
    /// no bias).
    Vec3d directLight(const Vec3d& ip, const Vec3d& dir)
    {
        Vec3d sum(0.0);
        for (size_t l = 0; l < mIn.lights.size(); ++l) {
            const Light& light = mIn.lights[l];
            if (light.type == Light::Type::Environment) continue;
            const double T = ratioTracking(ip, light);
            if (T > 0.0) sum += lightPhased(mIn, l, ip, dir) * T;
        }
        return sum;
    }

    /// The transmittance from index point ip toward `light`, unbiased, by ratio tracking against
    /// the majorants (Novak et al. 2014, as pbrt-v4): tentative collisions at the majorant's rate,
    /// each multiplying the estimate by the chance that it is null, 1 - sigma_t / sigma_majorant.
    /// Below 0.1 the estimate plays Russian roulette (survives with chance 1/2, doubled).
    double ratioTracking(const Vec3d& ip, const Light& light)
    {
        const Vec3d p = mIn.density.indexToWorld(ip);
        double distance; // world units
        const Vec3d toward = towardLight(light, p, distance);
        Vec3d dir = mIn.density.worldToIndex(p + toward) - ip; // index units per world unit
        const double scale = dir.length();
        dir /= scale;
        const double tMax = distance * scale; // voxels
        MajorantWalk walk(*mIn.majorants, *mR.majorants, ip, dir, 0.0);
        double T = 1.0, t0, t1;
        float majorant;
        while (walk.next(t0, t1, majorant) && t0 < tMax) {
            if (majorant <= 0.0f) continue;
            const double end = std::min(t1, tMax),
                         sigmaMajorant = mIn.sigmaPerVoxel * double(majorant);
            for (double t = t0;;) {
                t -= std::log1p(-mRandom.next()) / sigmaMajorant;
                if (t >= end) break;
                const double sigma =
                    mIn.sigmaPerVoxel * densityAt(mR.density, ip + dir * t, mIn.levelSet);
                T *= 1.0 - sigma / sigmaMajorant;
                if (T < 0.1) {
                    if (mRandom.next() >= 0.5) return 0.0;
                    T *= 2.0;
                }
            }
        }
        return T;
    }

    /// Russian roulette on the throughput's largest channel: false ends the path; a survivor's
    /// throughput is divided by its chance.
    bool survives(Vec3d& beta)
    {
        const double q = std::max({beta.x(), beta.y(), beta.z()});
        if (q >= 1.0) return true;
        if (mRandom.next() >= q) return false;
        beta /= q;
        return true;
    }

    /// Delta tracking from ip along dir (index space, unit): true with ip at the first real
    /// collision, false if the path leaves the volume.
    bool track(Vec3d& ip, const Vec3d& dir)
    {
        MajorantWalk walk(*mIn.majorants, *mR.majorants, ip, dir, 0.0);
        double t0, t1;
        float majorant;
        while (walk.next(t0, t1, majorant)) {
            if (majorant <= 0.0f) continue;
            const double sigmaMajorant = mIn.sigmaPerVoxel * double(majorant);
            for (double t = t0;;) {
                t -= std::log1p(-mRandom.next()) / sigmaMajorant;
                if (t >= t1) break;
                const Vec3d p = ip + dir * t;
                const double sigma = mIn.sigmaPerVoxel * densityAt(mR.density, p, mIn.levelSet);
                if (mRandom.next() * sigmaMajorant < sigma) {
                    ip = p;
                    return true;
                }
            }
        }
        return false;
    }

    ThreadReaders& mR;
    const FrameInputs& mIn;
    Random& mRandom;
};

} // namespace

RaySample tracePath(ThreadReaders& readers, const Ray& ray, Random& random)
{
    if (!readers.inter.setWorldRay(VdbRay(ray.origin, ray.direction))) return RaySample{};
    const Vec3d eye = readers.inter.getIndexPos(0.0);
    const Medium1D line{eye, readers.inter.getIndexPos(1.0) - eye, readers.in.levelSet};
    const double tau = walkPrimary(readers, line);
    RaySample out;
    out.T = std::exp(-tau);
    if (tau <= 0.0) return out;
    // The first collision, given one: optical depth -ln(1 - u (1 - T)), weight 1 - T.
    const double target = -std::log1p(-random.next() * (1.0 - out.T));
    const double t = invertPrimary(readers, line, std::min(target, tau));
    Path path(readers, random);
    // The weight applies outside the path, so that roulette sees the path's own attenuation.
    out.L = path.trace(line.eye + line.dir * t, line.dir) * (1.0 - out.T);
    return out;
}

} // namespace volmorph::render
