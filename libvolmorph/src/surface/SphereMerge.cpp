#include "SphereMerge.h"

#include "Landmarks.h"
#include "SphereLandmarks.h"
#include "SphereParam.h"
#include "SphereSides.h"

#include <stdexcept>

namespace volmorph::detail {
namespace {

SphereMap mapOf(const MergeSide& s, const SourceLocation& where, Interrupter* interrupter)
{
    try {
        return sphericalMap(s.points, s.triangles, interrupter);
    } catch (const std::runtime_error& e) {
        throw UserError(where, s.mesh->file.string() + ": " + e.what());
    }
}

/// A map's direction of a point of the surface: its triangle's corners' directions weighted
/// as the point is (the inverse of how mergeSides places a direction back on the surface).
Vec3d directionOf(const MergeSide& s, const SphereMap& map, const MergeSide::Place& p)
{
    const Vec3I& t = s.triangles[p.triangle];
    const Vec3d d = p.weights[0] * map.directions[t[0]] + p.weights[1] * map.directions[t[1]] +
                    p.weights[2] * map.directions[t[2]];
    return d / d.length();
}

} // namespace

Corresponded sphereMerge(const Mesh& source, const Mesh& target,
                         const std::vector<SurfaceLandmark>& landmarks, const SourceLocation& where,
                         Interrupter* interrupter)
{
    MergeSide a(source), b(target);
    const std::vector<MergeSide::Place> at = snapLandmarks(a, landmarks, true);
    snapLandmarks(b, landmarks, false); // the checks; each is placed once the last is in
    std::vector<uint32_t> targetVertices;
    for (const SurfaceLandmark& l : landmarks)
        targetVertices.push_back(b.insert(b.nearest(l.target)));
    const SphereMap ma = mapOf(a, where, interrupter);
    const SphereMap mb = mapOf(b, where, interrupter);
    std::vector<Vec3d> goals;
    for (size_t i = 0; i < landmarks.size(); ++i) goals.push_back(directionOf(a, ma, at[i]));
    std::vector<Vec3d> from;
    for (uint32_t v : targetVertices) from.push_back(mb.directions[v]);
    if (const auto m = mirroredLandmarks(from, goals)) {
        const std::vector<SurfaceLandmark> three = {landmarks[(*m)[0]], landmarks[(*m)[1]],
                                                    landmarks[(*m)[2]]};
        throw UserError(three.front().where,
                        "[[pair]]: the landmarks (" + landmarkPlaces(three) +
                            ") go round each other one way on " + source.file.string() +
                            " and the other way on " + target.file.string() +
                            " (mirrored): they cannot meet without folding the map");
    }
    std::vector<Vec3d> db = mb.directions;
    if (!pullToLandmarks(b.points, b.triangles, db, targetVertices, goals, interrupter))
        throw UserError(landmarks.front().where,
                        "[[pair]]: the landmarks (" + landmarkPlaces(landmarks) +
                            ") cannot all meet on " + target.file.string() +
                            "'s spherical map without folding it (are they in the "
                            "same order around each other on both meshes?)");
    SphereSide sa{&a, ma.directions, std::vector<double>(a.points.size(), 1.0)};
    SphereSide sb{&b, std::move(db), std::vector<double>(b.points.size(), 1.0)};
    const TurnedOver turnedOver = [&](bool, uint32_t bad) {
        // The maps turn nothing over (SphereParam checks it exactly); only the warp can.
        throw UserError(landmarks.front().where,
                        "[[pair]]: the landmarks (" + landmarkPlaces(landmarks) +
                            ") turn triangle " + std::to_string(bad) + " of " +
                            target.file.string() +
                            " over on the sphere: they cannot meet without folding the map");
    };
    Corresponded out = mergeSides(sa, sb, Correspondence::Sphere, turnedOver, where);
    out.stretch = std::pair{ma.stretchEfficiency, mb.stretchEfficiency};
    return out;
}

} // namespace volmorph::detail
