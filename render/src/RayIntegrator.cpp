#include "RayIntegrator.h"

#include "Cell.h"
#include "CellWalk.h"
#include "PropShading.h"
#include "Sampling.h"

#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <cmath>

namespace volmorph::render {

ThreadReaders::ThreadReaders(const FrameInputs& frame)
    : in(frame), inter(frame.master), density(frame.density.tree(), frame.padded),
      shadowInter(frame.master), shadowDensity(frame.density.tree(), frame.padded),
      perRay(frame.lights.size())
{
    if (frame.color) colors = std::make_unique<ColorReader>(frame.color->tree());
    if (frame.majorants)
        majorants = std::make_unique<Majorants::Accessor>(frame.majorants->accessor());
}

Vec3d towardLight(const Light& light, const Vec3d& p, double& distance)
{
    if (light.type != Light::Type::Point) {
        distance = 1e30;
        return -light.direction.unit();
    }
    const Vec3d toward = light.position - p;
    distance = toward.length();
    return toward / distance;
}

double exactVisibility(ThreadReaders& readers, const Vec3d& p, const Vec3d& w, double distance)
{
    const FrameInputs& in = readers.in;
    if (in.props && in.props->occluded(p, w, 0.0, distance)) return 0.0;
    return std::exp(-opticalDepth(readers.shadowInter, in.levelSet, readers.shadowDensity, p, w,
                                  distance, in.sigmaPerVoxel));
}

namespace {

/// The exact transmittance from index point ip toward `light` (no shadow map or cache: the march
/// through every cell on the way), 0 behind a prop.
double exactTransmittance(ThreadReaders& readers, const Light& light, const Vec3d& ip)
{
    const Vec3d p = readers.in.density.indexToWorld(ip);
    double distance;
    const Vec3d toward = towardLight(light, p, distance);
    return exactVisibility(readers, p, toward, distance);
}

} // namespace

Vec3d lightPhased(const FrameInputs& in, size_t l, const Vec3d& ip, const Vec3d& direction)
{
    const Light& light = in.lights[l];
    if (light.type == Light::Type::Point) {
        Vec3d travel = in.density.indexToWorld(ip) - light.position;
        const double d2 = travel.lengthSqr();
        travel /= std::sqrt(d2);
        return light.color * (light.intensity / d2 *
                              henyeyGreenstein(travel.dot(-direction), in.medium.anisotropy));
    }
    return light.color * (light.intensity * henyeyGreenstein(light.direction.unit().dot(-direction),
                                                             in.medium.anisotropy));
}

double lightArriving(ThreadReaders& readers, size_t l, const Vec3d& ip, const Vec3d& direction,
                     const Vec3d* directional, Vec3d& phased)
{
    const FrameInputs& in = readers.in;
    const Light& light = in.lights[l];
    const Shadow& shadow = in.shadows[l];
    phased = directional && light.type != Light::Type::Point ? *directional
                                                             : lightPhased(in, l, ip, direction);
    if (shadow.map) return shadow.map->lookup(ip);
    if (shadow.point) return shadow.point->lookup(ip);
    return exactTransmittance(readers, light, ip);
}

namespace {

/// The walk of one ray, and its state: transmittance and radiance so far, and the open run of steps
/// since the last knot. Each piece of the ray inside one interpolation cell (or constant block) is
/// cut into equal steps of at most stepVoxels. Each step's optical depth is exact (the integral of
/// the trilinear density, see Piece). The source S (emission plus albedo times the light reaching
/// the point) is evaluated at knots along the ray, at the first step end at least one voxel after
/// the previous knot (so 1 to 1 + h voxels apart), and taken linearly in between: each step adds
/// a = T (1 - e^-tau) times S at its middle. A and B sum a and a (t - knot) until the next knot,
/// which closes them. Constructed per ray, as a local, so that its state lives in registers.
class RayIntegrator {
public:
    RayIntegrator(ThreadReaders& readers, const Ray& ray, const Medium1D& line)
        : mR(readers), mIn(readers.in), mRay(ray), mLine(line)
    {
    }

    RaySample run()
    {
        double t0 = 0, t1 = 0;
        auto shade = [this](const Cell& cell, double ta, double tb) {
            return this->shade(cell, ta, tb);
        };
        while (mR.inter.march(t0, t1) && walkCells(mR.density, mLine, t0, t1, shade)) {}
        if (mOpen) close(mLastEnd);
        return mOut;
    }

    /// The ray time (voxels) at which the alpha passed 0.5, negative while it has not.
    double halfAlpha() const { return mHalf; }

private:
    /// The scattered part of the source term at ray time t (voxels): albedo times the light
    /// arriving. (The emission, constant, adds emission x (1 - T) over the ray: integrateVolume.)
    Vec3d sourceAt(double t)
    {
        const Vec3d ip = mLine.eye + mLine.dir * t;
        Vec3d albedo(mIn.medium.albedo);
        if (mR.colors) albedo = mR.colors->at(ip) * mIn.medium.albedo;
        Vec3d source(0.0);
        for (size_t l = 0; l < mIn.lights.size(); ++l) {
            Vec3d c;
            const double Tl = lightArriving(mR, l, ip, mRay.direction, &mR.perRay[l], c);
            source += Vec3d(albedo.x() * c.x(), albedo.y() * c.y(), albedo.z() * c.z()) * Tl;
        }
        return source;
    }

    /// A knot at t: settles the steps since the last one.
    void close(double t)
    {
        const Vec3d next = sourceAt(t);
        if (mA > 0.0)
            mOut.L.direct +=
                mKnotSource * mA + (next - mKnotSource) * (t > mKnot ? mB / (t - mKnot) : 0.0);
        mKnot = t;
        mKnotSource = next;
        mA = mB = 0.0;
    }

    /// Steps of one piece [ta, tb]: n steps of length dt, optical depth from tauOf(k, dt). Returns
    /// false when the ray is opaque enough to stop.
    template <typename TauOf>
    bool march(double ta, double tb, int n, TauOf&& tauOf)
    {
        if (!mOpen || ta != mLastEnd) { // a gap: settle the run before it
            if (mOpen) close(mLastEnd);
            mKnot = ta;
            mKnotSource = sourceAt(ta);
            mA = mB = 0.0;
            mOpen = true;
        }
        const double dt = (tb - ta) / n;
        double lastTau = -1.0, transmitted = 1.0;
        for (int k = 0; k < n; ++k) {
            const double tau = tauOf(k, dt);
            const double end = k + 1 == n ? tb : ta + (k + 1) * dt;
            if (tau > 0.0) {
                if (tau != lastTau) { // equal steps of a constant piece: once
                    lastTau = tau;
                    transmitted = expNegative(tau);
                }
                const double a = mOut.T * (1.0 - transmitted);
                mA += a;
                mB += a * (end - 0.5 * dt - mKnot);
                // Where T reaches 0.5, the step's density taken as uniform.
                if (mHalf < 0.0 && mOut.T * transmitted <= 0.5)
                    mHalf = ta + k * dt + dt * std::log(2.0 * mOut.T) / tau;
                mOut.T *= transmitted;
            }
            if (mOut.T <= kMinTransmittance) {
                close(end);
                mOpen = false;
                return false;
            }
            if (end - mKnot >= 1.0) close(end);
        }
        mLastEnd = tb;
        return true;
    }

    /// One piece [ta, tb] of the ray inside `cell` (or a constant run of cells).
    bool shade(const Cell& cell, double ta, double tb)
    {
        const double sigma = mIn.sigmaPerVoxel;
        const int n = std::max(1, int(std::ceil((tb - ta) / mIn.stepVoxels - 1e-9)));
        if (cell.block) {
            const double rho = mIn.levelSet ? (cell.lo < 0.0f ? 1.0 : 0.0) : double(cell.hi);
            return march(ta, tb, n, [&](int, double dt) { return sigma * rho * dt; });
        }
        const Piece piece(mLine, cell, ta);
        double before = 0.0; // piece.mass at the start of step k
        return march(ta, tb, n, [&](int k, double dt) {
            if (!piece.exact) return sigma * mLine.mass(cell, ta + k * dt, ta + (k + 1) * dt);
            const double after = piece.mass((k + 1) * dt);
            const double tau = sigma * (after - before);
            before = after;
            return tau;
        });
    }

    ThreadReaders& mR;
    const FrameInputs& mIn;
    const Ray& mRay;
    const Medium1D mLine;
    RaySample mOut;
    bool mOpen = false; ///< a knot is placed and steps since it are pending
    double mKnot = 0.0, mA = 0.0, mB = 0.0, mLastEnd = -1.0, mHalf = -1.0;
    Vec3d mKnotSource{0.0};
};

/// The volume's part of a camera ray, up to `tEnd` world units (a prop there, or none).
RaySample integrateVolume(ThreadReaders& readers, const Ray& ray, double tEnd)
{
    if (!readers.inter.setWorldRay(
            VdbRay(ray.origin, ray.direction, openvdb::math::Delta<double>::value(), tEnd)))
        return RaySample{};
    const FrameInputs& in = readers.in;
    // A directional light's phase and colour are constant along a ray.
    for (size_t l = 0; l < in.lights.size(); ++l) {
        const Light& light = in.lights[l];
        readers.perRay[l] =
            light.color *
            (light.intensity *
             henyeyGreenstein(light.direction.unit().dot(-ray.direction), in.medium.anisotropy));
    }
    const Medium1D line{readers.inter.getIndexPos(0.0),
                        readers.inter.getIndexPos(1.0) - readers.inter.getIndexPos(0.0),
                        in.levelSet};
    RayIntegrator integrator(readers, ray, line);
    RaySample out = integrator.run();
    out.L.emission = in.medium.emission * (1.0 - out.T);
    if (integrator.halfAlpha() >= 0.0)
        out.depth =
            (in.density.indexToWorld(line.eye + line.dir * integrator.halfAlpha()) - ray.origin)
                .length();
    return out;
}

} // namespace

RaySample integrateRay(ThreadReaders& readers, const Ray& ray, Random* random)
{
    const FrameInputs& in = readers.in;
    PropHit hit;
    const bool onProp =
        in.props && in.props->intersect(ray.origin, ray.direction, 0.0, kNoProp, hit);
    RaySample out = integrateVolume(readers, ray, onProp ? hit.distance : kNoProp);
    out.volumeL = out.L.sum();
    out.volumeT = out.T;
    if (!onProp || out.T <= kMinTransmittance) return out;
    const PropMesh& prop = in.props->mesh(hit.prop);
    Radiance surface;
    Vec3d unoccluded(0.0);
    double matte = 0.0;
    if (prop.role != PropMesh::Role::Holdout) {
        const Vec3d received =
            directIrradiance(readers, surfacePoint(ray, hit), hit.shading, unoccluded, random);
        surface.direct = diffuseRadiance(hit.reflectance, received);
        matte = shadowMatte(received, unoccluded);
    }
    finishOnProp(prop, hit.distance, surface, matte, out);
    return out;
}

} // namespace volmorph::render
