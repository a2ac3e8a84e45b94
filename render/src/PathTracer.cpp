#include "PathTracer.h"

#include "Cell.h"
#include "CellWalk.h"
#include "Majorants.h"
#include "PropShading.h"
#include "Shadows.h"

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
    return directionAround(d, cosTheta, 2.0 * M_PI * u2);
}

/// A direction drawn around unit normal n with density cos(theta) / pi (a diffuse surface's).
Vec3d cosineDirection(const Vec3d& n, double u1, double u2)
{
    return directionAround(n, std::sqrt(1.0 - u1), 2.0 * M_PI * u2);
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

constexpr double kLn2 = 0.69314718055994531;

/// The world distance along the camera ray at which its alpha passes 0.5 (its optical depth ln 2),
/// after walkPrimary found the total above that.
double halfAlphaDistance(const ThreadReaders& r, const Ray& ray, const Medium1D& line)
{
    const Vec3d ip = line.eye + line.dir * invertPrimary(r, line, kLn2);
    return (r.in.density.indexToWorld(ip) - ray.origin).length();
}

/// One path from the camera ray's first collision on: its radiance.
class Path {
public:
    Path(ThreadReaders& readers, Random& random) : mR(readers), mIn(readers.in), mRandom(random) {}

    /// Where a path is: a collision in the medium (index point ip, arrived along the unit index
    /// direction `dir`), or a point on a prop (world point x nudged off it, unit shading normal n
    /// facing the arrival, arrived along the unit world direction `dir`).
    struct Vertex {
        bool surface = false;
        Vec3d ip{0.0}, x{0.0}, n{0.0}, dir{0.0};
        Vec3d reflectance{0.0}; ///< a prop's, there
    };

    /// The radiance of the path from vertex `v` on (Cycles' bounces count every vertex): what
    /// reaches the first vertex from the lights and the environment is direct, the rest indirect.
    Radiance trace(Vertex v)
    {
        Radiance L;
        Vec3d beta(1.0);
        for (int vertex = 0;; ++vertex) {
            Vec3d& light = vertex == 0 ? L.direct : L.indirect;
            if (!scatter(v, vertex == 0 ? L.emission : L.indirect, light, beta)) break;
            if (vertex == mIn.bounces && !mIn.sky.any()) break;
            if (vertex >= 2 && !survives(beta)) break;
            if (!next(v)) {
                light += beta * escaping();
                break;
            }
            if (vertex == mIn.bounces) break;
        }
        return L;
    }

    /// The radiance leaving a diffuse prop's point x (shading normal n, reflectance r) toward -dir.
    Radiance onSurface(const Vec3d& x, const Vec3d& n, const Vec3d& dir, const Vec3d& r)
    {
        return trace(Vertex{true, Vec3d(0.0), x, n, dir, r});
    }

    /// A shadow catcher's matte at x (normal n): from the direct light on it, and the environment
    /// (a constant sky along one cosine-weighted direction, a map along one drawn from it), with
    /// and without the props and the volume.
    double catcherMatte(const Vec3d& x, const Vec3d& n)
    {
        Vec3d unoccluded;
        Vec3d received = directIrradiance(mR, x, n, unoccluded, &mRandom);
        const Sky& sky = mIn.sky;
        if (sky.constant != Vec3d(0.0)) {
            double u1, u2;
            mRandom.nextLD2(u1, u2);
            const Vec3d w = cosineDirection(n, u1, u2);
            const Vec3d E = sky.constant * M_PI; // a uniform sky's irradiance
            unoccluded += E;
            received += E * exactVisibility(mR, x, w, kNoProp);
        }
        if (sky.map) {
            double u1, u2, pdf;
            mRandom.nextLD2(u1, u2);
            const Vec3d w = sky.map->sample(u1, u2, pdf);
            const double cosine = n.dot(w);
            if (pdf > 0.0 && cosine > 0.0) {
                const Vec3d E = sky.mapRadiance(w) * (cosine / pdf);
                unoccluded += E;
                received += E * exactVisibility(mR, x, w, kNoProp);
            }
        }
        return shadowMatte(received, unoccluded);
    }

    /// A collision at index point ip, travelling along `dir` (index space).
    Radiance trace(const Vec3d& ip, const Vec3d& dir)
    {
        Vertex v;
        v.ip = ip;
        v.dir = dir;
        return trace(v);
    }

private:
    /// The vertex's emission into `emitted` and the light it scatters from the lights into `lit`,
    /// its albedo or reflectance into beta; false when nothing more can come back.
    bool scatter(const Vertex& v, Vec3d& emitted, Vec3d& lit, Vec3d& beta)
    {
        if (!v.surface) {
            emitted += beta * mIn.medium.emission;
            beta = beta * albedoAt(v.ip);
        } else {
            beta = beta * v.reflectance;
        }
        if (beta.x() <= 0.0 && beta.y() <= 0.0 && beta.z() <= 0.0) return false;
        if (!v.surface) {
            lit += beta * directLight(v.ip, v.dir);
        } else {
            Vec3d unoccluded;
            lit += diffuseRadiance(beta, directIrradiance(mR, v.x, v.n, unoccluded, &mRandom));
        }
        if (mIn.sky.map) lit += beta * skyLight(v);
        return true;
    }

    /// The next vertex from `v`: a new direction (the phase function's in the medium, cosine
    /// weighted on a diffuse prop, both sampled exactly), then the first collision or prop along
    /// it. False when the path leaves everything.
    bool next(Vertex& v)
    {
        if (!v.surface) {
            double u1, u2;
            mRandom.nextLD2(u1, u2);
            const Vec3d dir = sampleHenyeyGreenstein(v.dir, mIn.medium.anisotropy, u1, u2);
            mPdf = henyeyGreenstein(v.dir.dot(dir), mIn.medium.anisotropy);
            if (!mIn.props) { // the medium alone, in index space
                if (track(v.ip, dir, kNoProp)) {
                    v.dir = dir;
                    return true;
                }
                if (mIn.sky.map) mEscape = worldDirection(v.ip, dir);
                return false;
            }
            return go(mIn.density.indexToWorld(v.ip), worldDirection(v.ip, dir), v);
        }
        double u1, u2;
        mRandom.nextLD2(u1, u2);
        const Vec3d w = cosineDirection(v.n, u1, u2);
        mPdf = v.n.dot(w) / M_PI;
        return go(v.x, w, v);
    }

    /// The unit world direction of unit index direction `dir` at index point ip.
    Vec3d worldDirection(const Vec3d& ip, const Vec3d& dir) const
    {
        return (mIn.density.indexToWorld(ip + dir) - mIn.density.indexToWorld(ip)).unit();
    }

    /// The environment's radiance along the direction the path left everything by (mEscape,
    /// drawn with density mPdf): a map's weighted against skyLight's chance of drawing it.
    Vec3d escaping() const
    {
        const Sky& sky = mIn.sky;
        if (!sky.map) return sky.constant;
        return sky.constant +
               sky.mapRadiance(mEscape) * powerHeuristic(mPdf, sky.map->pdf(mEscape));
    }

    /// Next-event estimation toward the sky map from vertex v: one direction drawn from the map,
    /// weighted against the phase function's (or a diffuse surface's cosine's) chance of drawing
    /// it (power heuristic), through the medium's transmittance (ratio tracking from a collision,
    /// exact from a surface) and the props. Per unit throughput, reflectance already in it.
    Vec3d skyLight(const Vertex& v)
    {
        const Sky& sky = mIn.sky;
        double u1, u2, pdf;
        mRandom.nextLD2(u1, u2);
        const Vec3d w = sky.map->sample(u1, u2, pdf);
        if (pdf <= 0.0) return Vec3d(0.0);
        double f = 0.0, T = 0.0;
        if (v.surface) {
            f = v.n.dot(w) / M_PI;
            if (f <= 0.0) return Vec3d(0.0);
            T = exactVisibility(mR, v.x, w, kNoProp);
        } else {
            const Vec3d x = mIn.density.indexToWorld(v.ip);
            const Vec3d dir = (mIn.density.worldToIndex(x + w) - v.ip).unit();
            f = henyeyGreenstein(v.dir.dot(dir), mIn.medium.anisotropy);
            T = transmittance(v.ip, w, kNoProp);
        }
        if (T <= 0.0) return Vec3d(0.0);
        return sky.mapRadiance(w) * (f * T / pdf * powerHeuristic(pdf, f));
    }

    /// From world point x along unit world direction w: the first collision before the first prop
    /// (into `v`), else the prop; false when neither.
    bool go(const Vec3d& x, const Vec3d& w, Vertex& v)
    {
        PropHit hit;
        const bool onProp = mIn.props->intersect(x, w, 0.0, kNoProp, hit);
        mEscape = w;
        const Vec3d ip = mIn.density.worldToIndex(x);
        Vec3d dir = mIn.density.worldToIndex(x + w) - ip;
        const double scale = dir.length(); // voxels per world unit
        dir /= scale;
        Vec3d at = ip;
        if (track(at, dir, onProp ? hit.distance * scale : kNoProp)) {
            v = Vertex{false, at, Vec3d(0.0), Vec3d(0.0), dir, Vec3d(0.0)};
            return true;
        }
        if (!onProp) return false;
        v = Vertex{true, Vec3d(0.0), surfacePoint(Ray{x, w}, hit), hit.shading, w, hit.reflectance};
        return true;
    }

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

    /// The transmittance from index point ip toward `light` (a soft sun's direction drawn over
    /// its disc), as transmittance() estimates it.
    double ratioTracking(const Vec3d& ip, const Light& light)
    {
        double distance; // world units
        const Vec3d toward = sampleLight(
            light, towardLight(light, mIn.density.indexToWorld(ip), distance), &mRandom);
        return transmittance(ip, toward, distance);
    }

    /// The transmittance from index point ip along unit world direction `toward` for `distance`
    /// world units: 0 where a prop blocks the way, else unbiased, by ratio tracking against the
    /// majorants (Novak et al. 2014, as pbrt-v4): tentative collisions at the majorant's rate,
    /// each multiplying the estimate by the chance that it is null, 1 - sigma_t / sigma_majorant.
    /// Below 0.1 the estimate plays Russian roulette (survives with chance 1/2, doubled).
    double transmittance(const Vec3d& ip, const Vec3d& toward, double distance)
    {
        const Vec3d p = mIn.density.indexToWorld(ip);
        if (mIn.props && mIn.props->occluded(p, toward, 0.0, distance)) return 0.0;
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

    /// Delta tracking from ip along dir (index space, unit) up to ray time tMax (voxels): true with
    /// ip at the first real collision, false if the path leaves the volume before.
    bool track(Vec3d& ip, const Vec3d& dir, double tMax)
    {
        MajorantWalk walk(*mIn.majorants, *mR.majorants, ip, dir, 0.0);
        double t0, t1;
        float majorant;
        while (walk.next(t0, t1, majorant) && t0 < tMax) {
            if (majorant <= 0.0f) continue;
            const double sigmaMajorant = mIn.sigmaPerVoxel * double(majorant),
                         end = std::min(t1, tMax);
            for (double t = t0;;) {
                t -= std::log1p(-mRandom.next()) / sigmaMajorant;
                if (t >= end) break;
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
    double mPdf = 0.0;  ///< the density (per steradian) of the direction next() drew last
    Vec3d mEscape{0.0}; ///< the world direction by which the path last left everything
};

} // namespace

RaySample tracePath(ThreadReaders& readers, const Ray& ray, Random& random)
{
    const FrameInputs& in = readers.in;
    PropHit hit;
    const bool onProp =
        in.props && in.props->intersect(ray.origin, ray.direction, 0.0, kNoProp, hit);
    RaySample out;
    Path path(readers, random);
    if (readers.inter.setWorldRay(VdbRay(ray.origin, ray.direction,
                                         openvdb::math::Delta<double>::value(),
                                         onProp ? hit.distance : kNoProp))) {
        const Vec3d eye = readers.inter.getIndexPos(0.0);
        const Medium1D line{eye, readers.inter.getIndexPos(1.0) - eye, in.levelSet};
        const double tau = walkPrimary(readers, line);
        out.T = std::exp(-tau);
        if (tau > 0.0) {
            // The first collision, given one: optical depth -ln(1 - u (1 - T)), weight 1 - T.
            const double target = -std::log1p(-random.nextLD() * (1.0 - out.T));
            const double t = invertPrimary(readers, line, std::min(target, tau));
            // The weight applies outside the path, so that roulette sees the path's own
            // attenuation.
            out.L = path.trace(line.eye + line.dir * t, line.dir);
            out.L *= 1.0 - out.T;
        }
        if (tau > kLn2) out.depth = halfAlphaDistance(readers, ray, line);
    }
    out.volumeL = out.L.sum();
    out.volumeT = out.T;
    if (!onProp || out.T <= kMinTransmittance) return out;
    const PropMesh& prop = in.props->mesh(hit.prop);
    Radiance surface;
    double matte = 0.0;
    if (prop.role == PropMesh::Role::Diffuse)
        surface =
            path.onSurface(surfacePoint(ray, hit), hit.shading, ray.direction, hit.reflectance);
    else if (prop.role == PropMesh::Role::ShadowCatcher)
        matte = path.catcherMatte(surfacePoint(ray, hit), hit.normal);
    finishOnProp(prop, hit.distance, surface, matte, out);
    return out;
}

} // namespace volmorph::render
