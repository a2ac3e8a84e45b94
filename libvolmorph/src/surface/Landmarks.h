// Landmarks for the merged correspondences: a scene's point pairs, each point snapped to its mesh,
// made a vertex of the target, and a map of the target's parameter domain that takes each target
// landmark onto its source landmark, so that the pair meets in the merged mesh.
#pragma once

#include "MergeSide.h"

#include <volmorph/SurfaceSettings.h>

#include <Eigen/Core>

#include <vector>

namespace volmorph::detail {

/// Where each landmark's `source` (or `target`) point lies on `side`. Throws UserError at the
/// landmark's pair naming the mesh when a point is off the surface by more than a tenth of the
/// mesh's size.
std::vector<MergeSide::Place>
snapLandmarks(const MergeSide& side, const std::vector<SurfaceLandmark>& landmarks, bool source);

/// The turn that best takes each from[i] onto to[i] (unit vectors; Kabsch, for one pair the
/// least turn; the identity for none).
Eigen::Matrix3d landmarkTurn(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to);

/// A smooth map of the unit sphere that takes each from[i] to to[i] (unit vectors): the rotation
/// that best aligns them (Kabsch; for one pair, the least turn), then a flow of kSteps small
/// warps, each a sum of Gaussian bumps fitted so that every landmark moves a step along its great
/// circle to its target (projected back onto the sphere), the last step landing each exactly.
/// Small steps keep each warp's gradient small, so the flow stays one-to-one where the landmarks
/// are consistent; the caller checks the warped triangles.
class SphereWarp {
public:
    static constexpr int kSteps = 32;
    SphereWarp(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to);
    Vec3d operator()(const Vec3d& direction) const;

private:
    struct Step {
        std::vector<Eigen::Vector3d> centres;
        Eigen::MatrixXd weights; ///< per centre, a displacement (rows)
    };
    static Eigen::Vector3d apply(const Step& step, const Eigen::Vector3d& x);

    Eigen::Matrix3d mRotation = Eigen::Matrix3d::Identity();
    std::vector<Step> mSteps;
    static constexpr double kWidth = 0.5; ///< the bumps' width, chord length on the unit sphere
};

/// The same flow in the unit disk, for the disk correspondence: each step's bumps are scaled by
/// 1 - |x|^2, so the boundary circle stays where it is and the disk maps onto itself; each landmark
/// moves along the straight line to its target (which must be inside the circle).
class DiskWarp {
public:
    static constexpr int kSteps = 32;
    DiskWarp(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to);
    Eigen::Vector2d operator()(const Eigen::Vector2d& p) const;

private:
    struct Step {
        std::vector<Eigen::Vector2d> centres;
        Eigen::MatrixXd weights;
    };
    static Eigen::Vector2d apply(const Step& step, const Eigen::Vector2d& x);

    std::vector<Step> mSteps;
    static constexpr double kWidth = 0.5;
};

/// "scene.toml:3:1, scene.toml:9:1": the landmarks' pairs, for messages.
std::string landmarkPlaces(const std::vector<SurfaceLandmark>& landmarks);

} // namespace volmorph::detail
