#include "Landmarks.h"

#include <Eigen/Dense>

#include <cmath>

namespace volmorph::detail {

std::vector<MergeSide::Place>
snapLandmarks(const MergeSide& side, const std::vector<SurfaceLandmark>& landmarks, bool source)
{
    std::vector<MergeSide::Place> out;
    for (const SurfaceLandmark& l : landmarks) {
        const Vec3d& p = source ? l.source : l.target;
        const MergeSide::Place at = side.nearest(p);
        if (at.distance > 0.1 * side.diagonal)
            throw UserError(
                l.where, std::string("[[pair]]: the ") + (source ? "source" : "target") +
                             " landmark " + pointText(p) + " is " + std::to_string(at.distance) +
                             " world units off " + side.mesh->file.string() +
                             ", more than a tenth of its size (" + std::to_string(side.diagonal) +
                             "); a landmark is a point of the surface");
        out.push_back(at);
    }
    return out;
}

namespace {

Eigen::Vector3d eig(const Vec3d& v)
{
    return {v.x(), v.y(), v.z()};
}

} // namespace

Eigen::Matrix3d landmarkTurn(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to)
{
    if (from.empty()) return Eigen::Matrix3d::Identity();
    if (from.size() == 1)
        return Eigen::Quaterniond::FromTwoVectors(eig(from[0]), eig(to[0])).toRotationMatrix();
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < from.size(); ++i) h += eig(from[i]) * eig(to[i]).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    return svd.matrixV() * d * svd.matrixU().transpose();
}

SphereWarp::SphereWarp(const std::vector<Vec3d>& from, const std::vector<Vec3d>& to)
{
    if (from.empty()) return;
    mRotation = landmarkTurn(from, to);
    const size_t n = from.size();
    std::vector<Eigen::Vector3d> at(n);
    for (size_t i = 0; i < n; ++i) at[i] = mRotation * eig(from[i]);
    Eigen::MatrixXd phi(n, n);
    for (int k = 0; k < kSteps; ++k) {
        Step step;
        step.centres = at;
        Eigen::MatrixXd rhs(n, 3);
        for (size_t i = 0; i < n; ++i) {
            // A 1 / (steps left) share of the way along the great circle to the target.
            const Eigen::Vector3d goal = eig(to[i]);
            const double angle = std::atan2(at[i].cross(goal).norm(), at[i].dot(goal));
            const double share = 1.0 / double(kSteps - k);
            Eigen::Vector3d next = goal;
            if (angle > 1e-15 && share < 1.0) {
                const double s = std::sin(angle);
                next = (std::sin((1.0 - share) * angle) / s) * at[i] +
                       (std::sin(share * angle) / s) * goal;
            }
            rhs.row(Eigen::Index(i)) = (next - at[i]).transpose();
            for (size_t j = 0; j < n; ++j) {
                const double r = (at[i] - at[j]).norm() / kWidth;
                phi(Eigen::Index(i), Eigen::Index(j)) = std::exp(-r * r);
            }
        }
        step.weights = phi.fullPivLu().solve(rhs); // a Gaussian's matrix is positive definite
        for (size_t i = 0; i < n; ++i) at[i] = apply(step, at[i]);
        mSteps.push_back(std::move(step));
    }
}

Eigen::Vector3d SphereWarp::apply(const Step& step, const Eigen::Vector3d& x)
{
    Eigen::Vector3d moved = x;
    for (size_t i = 0; i < step.centres.size(); ++i) {
        const double r = (x - step.centres[i]).norm() / kWidth;
        moved += std::exp(-r * r) * step.weights.row(Eigen::Index(i)).transpose();
    }
    return moved.normalized();
}

Vec3d SphereWarp::operator()(const Vec3d& direction) const
{
    Eigen::Vector3d x = mRotation * eig(direction);
    for (const Step& step : mSteps) x = apply(step, x);
    return {x.x(), x.y(), x.z()};
}

DiskWarp::DiskWarp(const std::vector<Eigen::Vector2d>& from, const std::vector<Eigen::Vector2d>& to)
{
    const size_t n = from.size();
    std::vector<Eigen::Vector2d> at = from;
    Eigen::MatrixXd m(n, n), rhs(n, 2);
    for (int k = 0; k < kSteps && n > 0; ++k) {
        Step step;
        step.centres = at;
        for (size_t i = 0; i < n; ++i) {
            rhs.row(Eigen::Index(i)) = ((to[i] - at[i]) / double(kSteps - k)).transpose();
            const double damp = 1.0 - at[i].squaredNorm();
            for (size_t j = 0; j < n; ++j) {
                const double r = (at[i] - at[j]).norm() / kWidth;
                m(Eigen::Index(i), Eigen::Index(j)) = damp * std::exp(-r * r);
            }
        }
        step.weights = m.fullPivLu().solve(rhs);
        for (size_t i = 0; i < n; ++i) at[i] = apply(step, at[i]);
        mSteps.push_back(std::move(step));
    }
}

Eigen::Vector2d DiskWarp::apply(const Step& step, const Eigen::Vector2d& x)
{
    Eigen::Vector2d bump = Eigen::Vector2d::Zero();
    for (size_t i = 0; i < step.centres.size(); ++i) {
        const double r = (x - step.centres[i]).norm() / kWidth;
        bump += std::exp(-r * r) * step.weights.row(Eigen::Index(i)).transpose();
    }
    return x + (1.0 - x.squaredNorm()) * bump;
}

Eigen::Vector2d DiskWarp::operator()(const Eigen::Vector2d& p) const
{
    Eigen::Vector2d x = p;
    for (const Step& step : mSteps) x = apply(step, x);
    return x;
}

std::string landmarkPlaces(const std::vector<SurfaceLandmark>& landmarks)
{
    std::string out;
    for (const SurfaceLandmark& l : landmarks) out += (out.empty() ? "" : ", ") + l.where.str();
    return out;
}

} // namespace volmorph::detail
