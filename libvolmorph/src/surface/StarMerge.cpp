#include "StarMerge.h"

#include "Landmarks.h"
#include "MergeSide.h"
#include "SphereSides.h"

#include <stdexcept>

namespace volmorph::detail {
namespace {

using Side = MergeSide;

KernelPoint kernelOf(const Side& s, const std::optional<Vec3d>& given)
{
    return given ? kernelDepth(s.points, s.triangles, *given)
                 : deepestKernelPoint(s.points, s.triangles);
}

void requireStarShaped(const Side& s, const KernelPoint& k, bool given, const SourceLocation& where)
{
    if (k.margin > 1e-9 * s.diagonal) return;
    const Vec3I& t = s.triangles[k.worstTriangle];
    const std::string face =
        "triangle " + std::to_string(k.worstTriangle) + " (vertices " +
        std::to_string(s.original[t[0]]) + ", " + std::to_string(s.original[t[1]]) + ", " +
        std::to_string(s.original[t[2]]) + ") faces away from it, so vertex " +
        std::to_string(s.original[t[0]]) + " at " + pointText(s.points[t[0]]) + " cannot be seen";
    if (given)
        throw UserError(where, "surface.kernel: " + s.mesh->file.string() +
                                   " is not seen whole from " + pointText(k.point) + ": " + face);
    throw UserError(
        where, s.mesh->file.string() +
                   " is not star-shaped: no point sees all of its surface (from " +
                   pointText(k.point) + ", the point nearest to it, " + face +
                   "); correspondence = \"sphere\" (the spherical map) takes any closed genus-0 "
                   "mesh");
}

/// A side seen from `kernel`: its vertices' unit directions, moved by `warp` (the landmarks'),
/// and their distances from it.
SphereSide seen(const Side& s, const Vec3d& kernel, const SphereWarp& warp)
{
    SphereSide out;
    out.side = &s;
    for (const Vec3d& p : s.points) {
        Vec3d d = p - kernel;
        out.depth.push_back(d.length());
        d.normalize();
        out.directions.push_back(warp(d));
    }
    return out;
}

std::string edgeOn(const Side& s, const Vec3d& kernel, uint32_t triangle)
{
    return s.mesh->file.string() + ": triangle " + std::to_string(triangle) +
           " is seen edge-on from " + pointText(kernel) + " (too thin to project)";
}

} // namespace

namespace {

/// The target's landmarks made vertices, and the warp of its sphere that takes each onto the
/// source's landmark there.
SphereWarp landmarkWarp(const Side& a, const Vec3d& ka, Side& b, const Vec3d& kb,
                        const std::vector<SurfaceLandmark>& landmarks)
{
    std::vector<Vec3d> from, to;
    for (const MergeSide::Place& p : snapLandmarks(a, landmarks, true)) {
        Vec3d d = p.point - ka;
        to.push_back(d / d.length());
    }
    snapLandmarks(b, landmarks, false); // the checks; each is placed once the last is in
    for (const SurfaceLandmark& l : landmarks) {
        Vec3d d = b.points[b.insert(b.nearest(l.target))] - kb;
        from.push_back(d / d.length());
    }
    return SphereWarp(from, to);
}

} // namespace

Corresponded starMerge(const Mesh& source, const Mesh& target,
                       const std::optional<std::pair<Vec3d, Vec3d>>& kernels,
                       const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where)
{
    Side a(source), b(target);
    const KernelPoint ka =
        kernelOf(a, kernels ? std::optional<Vec3d>(kernels->first) : std::nullopt);
    const KernelPoint kb =
        kernelOf(b, kernels ? std::optional<Vec3d>(kernels->second) : std::nullopt);
    requireStarShaped(a, ka, kernels.has_value(), where);
    requireStarShaped(b, kb, kernels.has_value(), where);
    const SphereWarp warp = landmarkWarp(a, ka.point, b, kb.point, landmarks);
    const TurnedOver turnedOver = [&](bool isSource, uint32_t bad) {
        if (isSource || landmarks.empty())
            throw UserError(where, isSource ? edgeOn(a, ka.point, bad) : edgeOn(b, kb.point, bad));
        throw UserError(landmarks.front().where,
                        "[[pair]]: the landmarks (" + landmarkPlaces(landmarks) +
                            ") turn triangle " + std::to_string(bad) + " of " +
                            target.file.string() +
                            " over on the sphere: they cannot meet without folding the map");
    };
    Corresponded out = mergeSides(seen(a, ka.point, SphereWarp({}, {})), seen(b, kb.point, warp),
                                  Correspondence::Star, turnedOver, where);
    out.kernels = std::pair{ka.point, kb.point};
    return out;
}

} // namespace volmorph::detail
