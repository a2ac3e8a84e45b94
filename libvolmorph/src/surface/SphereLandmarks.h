// Landmarks in the spherical map: the target's map turned and relaxed until each landmark vertex
// sits where the source's landmark lies on the source's map, by continuation: the landmarks move
// a share of the way along their great circles at each of kSteps steps (as far as their triangles
// allow) and every other vertex relaxes its stretch around them (SphereStretch.h), so the map
// stays one-to-one throughout and is, at the end, the least-stretched the relaxation finds with
// the landmarks pinned.
#pragma once

#include <volmorph/core/Interrupter.h>
#include <volmorph/core/Math.h>

#include <array>
#include <optional>
#include <vector>

namespace volmorph::detail {

/// Landmarks placed mirrored: every three of them whose triangles are clear of a great circle
/// on both maps (|det| > kClearTriple) go round each other one way on one map (`from`, the
/// target's) and the other way on the other (`goals`, the source's). A one-to-one map could only
/// meet them by twisting the surface round itself. The first such three, or none.
inline constexpr double kClearTriple = 0.02;
std::optional<std::array<size_t, 3>> mirroredLandmarks(const std::vector<Vec3d>& from,
                                                       const std::vector<Vec3d>& goals);

/// Moves `directions` (a one-to-one map of `triangles` of `points`) so that directions[vertices[i]]
/// == goals[i] exactly: first the best turn of the landmarks onto their goals, then the pull.
/// Returns false, the map still one-to-one, when a landmark cannot reach its goal without turning
/// a triangle over (the landmarks are not in the same order around each other as their goals).
bool pullToLandmarks(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                     std::vector<Vec3d>& directions, const std::vector<uint32_t>& vertices,
                     const std::vector<Vec3d>& goals, Interrupter* interrupter = nullptr);

} // namespace volmorph::detail
