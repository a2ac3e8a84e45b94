#include "RigidInterpolation.h"

#include "Cotangent.h"
#include "mesh/DisjointSets.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace volmorph::detail {
namespace {

Eigen::Vector3d toEigen(const Vec3d& p)
{
    return {p.x(), p.y(), p.z()};
}

/// A triangle's frame: its two edges from its first vertex and a normal scaled by the square root
/// of its double area (Sumner and Popovic 2004), so that the frame's volume grows with the area.
/// Zero for a triangle without area.
bool triangleFrame(const std::vector<Vec3d>& points, const Vec3I& t, Eigen::Matrix3d& frame)
{
    const Eigen::Vector3d p0 = toEigen(points[t[0]]);
    const Eigen::Vector3d e1 = toEigen(points[t[1]]) - p0;
    const Eigen::Vector3d e2 = toEigen(points[t[2]]) - p0;
    const Eigen::Vector3d c = e1.cross(e2);
    const double area2 = c.norm();
    if (!(area2 > 1e-300)) return false;
    frame.col(0) = e1;
    frame.col(1) = e2;
    frame.col(2) = c / std::sqrt(area2);
    return true;
}

Eigen::Matrix3d cross(const Eigen::Vector3d& k)
{
    Eigen::Matrix3d m;
    m << 0.0, -k.z(), k.y(), k.z(), 0.0, -k.x(), -k.y(), k.x(), 0.0;
    return m;
}

} // namespace

namespace {

/// The polar decomposition of a triangle's map from source to target, and its rotation's axis and
/// angle.
RigidInterpolation::Triangle decompose(const std::vector<Vec3d>& source,
                                       const std::vector<Vec3d>& target, const Vec3I& t)
{
    RigidInterpolation::Triangle tri;
    Eigen::Matrix3d p, q;
    if (!triangleFrame(source, t, p) || !triangleFrame(target, t, q)) {
        tri.rotation = tri.stretch = Eigen::Matrix3d::Identity();
        tri.axis = Eigen::Vector3d::UnitZ();
        return tri;
    }
    // A = Q P^-1 = R S; R = U V^T (a rotation: both frames are right-handed), S = V Sigma V^T.
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(q * p.inverse(),
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    Eigen::Vector3d sigma = svd.singularValues();
    const Eigen::Matrix3d& v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0.0) {
        u.col(2) = -u.col(2);
        sigma(2) = -sigma(2);
    }
    tri.rotation = u * v.transpose();
    tri.stretch = v * sigma.asDiagonal() * v.transpose();
    const Eigen::AngleAxisd turn(tri.rotation);
    tri.axis = turn.axis();
    tri.angle = turn.angle();
    return tri;
}

} // namespace

RigidInterpolation::RigidInterpolation(const std::vector<Vec3d>& source,
                                       const std::vector<Vec3d>& target,
                                       const std::vector<Vec3I>& triangles)
{
    findPieces(source, target, triangles);
    mSource = source;
    mTarget = target;
    mCorners = triangles;
    mTriangles.resize(triangles.size());
    tbb::parallel_for(size_t(0), triangles.size(),
                      [&](size_t j) { mTriangles[j] = decompose(source, target, triangles[j]); });
    double meanEdge = 0.0;
    for (const Vec3I& t : triangles)
        for (int c = 0; c < 3; ++c) meanEdge += (source[t[c]] - source[t[(c + 1) % 3]]).length();
    meanEdge /= double(std::max<size_t>(1, 3 * triangles.size()));
    std::vector<Eigen::Triplet<double>> entries;
    const double delta = 1e-4 * meanEdge; // Sharp and Crane's choice
    forEachMollifiedCotangentWeight(
        source, triangles, delta, [&](uint32_t j, uint32_t a, uint32_t b, double w) {
            mEdges.push_back({a, b, j, w, toEigen(source[a]) - toEigen(source[b])});
            const int ra = mFree[a], rb = mFree[b];
            if (ra >= 0) entries.emplace_back(ra, ra, w);
            if (rb >= 0) entries.emplace_back(rb, rb, w);
            if (ra >= 0 && rb >= 0) {
                entries.emplace_back(ra, rb, -w);
                entries.emplace_back(rb, ra, -w);
            }
        });
    if (mRows > 0) {
        Eigen::SparseMatrix<double> laplacian(mRows, mRows);
        laplacian.setFromTriplets(entries.begin(), entries.end());
        mSolver.compute(laplacian);
        if (mSolver.info() != Eigen::Success)
            throw std::runtime_error("the mesh's cotangent Laplacian cannot be factored");
    }
    // What the fit misses of each end (rounding, and triangles too thin to have a frame): taken
    // out along the straight line, so that tau = 0 and 1 are the inputs.
    std::vector<Vec3d> velocity;
    solveAt(0.0, mMissed0, velocity);
    solveAt(1.0, mMissed1, velocity);
    for (size_t v = 0; v < source.size(); ++v) {
        mMissed0[v] -= source[v];
        mMissed1[v] -= target[v];
    }
}

void RigidInterpolation::findPieces(const std::vector<Vec3d>& source,
                                    const std::vector<Vec3d>& target,
                                    const std::vector<Vec3I>& triangles)
{
    const size_t n = source.size();
    // A vertex of each piece is held at the origin (the energy does not see translations).
    DisjointSets sets(n);
    for (const Vec3I& t : triangles) {
        sets.unite(t[0], t[1]);
        sets.unite(t[1], t[2]);
    }
    std::vector<int> pieceOfRoot(n, -1);
    mPiece.resize(n);
    mFree.assign(n, -1);
    for (uint32_t v = 0; v < n; ++v) {
        int& piece = pieceOfRoot[sets.find(v)];
        if (piece < 0) { // the piece's first vertex: held
            piece = int(mSourceMean.size());
            mSourceMean.emplace_back(Eigen::Vector3d::Zero());
            mTargetMean.emplace_back(Eigen::Vector3d::Zero());
            mPieceSize.push_back(0.0);
        } else {
            mFree[v] = mRows++;
        }
        mPiece[v] = uint32_t(piece);
        mSourceMean[piece] += toEigen(source[v]);
        mTargetMean[piece] += toEigen(target[v]);
        mPieceSize[piece] += 1.0;
    }
    for (size_t i = 0; i < mPieceSize.size(); ++i) {
        mSourceMean[i] /= mPieceSize[i];
        mTargetMean[i] /= mPieceSize[i];
    }
}

void RigidInterpolation::rightHandSide(const Times& times, Eigen::MatrixXd& rhs) const
{
    // Per triangle G(tau) and dG/dtau times its rate, from one rotation and one stretch.
    std::vector<Eigen::Matrix3d> g(mTriangles.size()), dg(mTriangles.size());
    tbb::parallel_for(size_t(0), mTriangles.size(), [&](size_t j) {
        const Triangle& t = mTriangles[j];
        const double tau = times.tau[j];
        const Eigen::Matrix3d turn = Eigen::AngleAxisd(tau * t.angle, t.axis).toRotationMatrix();
        const Eigen::Matrix3d stretch = (1.0 - tau) * Eigen::Matrix3d::Identity() + tau * t.stretch;
        g[j] = turn * stretch;
        dg[j] = t.angle * cross(t.axis) * g[j] + turn * (t.stretch - Eigen::Matrix3d::Identity());
        if (times.rate[j] != 1.0) dg[j] *= times.rate[j];
    });
    rhs.setZero(mRows, 6);
    for (const Edge& e : mEdges) {
        Eigen::Matrix<double, 1, 6> wg;
        wg << (g[e.triangle] * e.edge).transpose(), (dg[e.triangle] * e.edge).transpose();
        wg *= e.weight;
        if (mFree[e.a] >= 0) rhs.row(mFree[e.a]) += wg;
        if (mFree[e.b] >= 0) rhs.row(mFree[e.b]) -= wg;
    }
}

void RigidInterpolation::positions(double tau, std::vector<Vec3d>& out,
                                   std::vector<Vec3d>& velocity) const
{
    solveAt(tau, out, velocity);
    for (size_t v = 0; v < out.size(); ++v) {
        out[v] -= (1.0 - tau) * mMissed0[v] + tau * mMissed1[v];
        velocity[v] -= mMissed1[v] - mMissed0[v];
    }
}

void RigidInterpolation::positions(const std::vector<double>& vertexTau,
                                   const std::vector<double>& vertexRate, std::vector<Vec3d>& out,
                                   std::vector<Vec3d>& velocity) const
{
    // Each triangle at its corners' mean tau; each piece's mean on the mean of its vertices'
    // straight lines, each at its own tau.
    Times times;
    times.tau.resize(mCorners.size());
    times.rate.resize(mCorners.size());
    for (size_t j = 0; j < mCorners.size(); ++j) {
        const Vec3I& c = mCorners[j];
        times.tau[j] = (vertexTau[c[0]] + vertexTau[c[1]] + vertexTau[c[2]]) / 3.0;
        times.rate[j] = (vertexRate[c[0]] + vertexRate[c[1]] + vertexRate[c[2]]) / 3.0;
    }
    times.centre.assign(mPieceSize.size(), Eigen::Vector3d::Zero());
    times.drift.assign(mPieceSize.size(), Eigen::Vector3d::Zero());
    for (size_t v = 0; v < mSource.size(); ++v) {
        const Eigen::Vector3d a = toEigen(mSource[v]), b = toEigen(mTarget[v]);
        times.centre[mPiece[v]] += (a + vertexTau[v] * (b - a)) / mPieceSize[mPiece[v]];
        times.drift[mPiece[v]] += (b - a) * (vertexRate[v] / mPieceSize[mPiece[v]]);
    }
    solve(times, out, velocity);
    for (size_t v = 0; v < out.size(); ++v) {
        out[v] -= (1.0 - vertexTau[v]) * mMissed0[v] + vertexTau[v] * mMissed1[v];
        velocity[v] -= (mMissed1[v] - mMissed0[v]) * vertexRate[v];
    }
}

void RigidInterpolation::solveAt(double tau, std::vector<Vec3d>& out,
                                 std::vector<Vec3d>& velocity) const
{
    Times times;
    times.tau.assign(mTriangles.size(), tau);
    times.rate.assign(mTriangles.size(), 1.0);
    times.centre.resize(mPieceSize.size());
    times.drift.resize(mPieceSize.size());
    for (size_t p = 0; p < mPieceSize.size(); ++p) {
        times.centre[p] = (1.0 - tau) * mSourceMean[p] + tau * mTargetMean[p];
        times.drift[p] = mTargetMean[p] - mSourceMean[p];
    }
    solve(times, out, velocity);
}

void RigidInterpolation::solve(const Times& times, std::vector<Vec3d>& out,
                               std::vector<Vec3d>& velocity) const
{
    const size_t n = mFree.size();
    // Columns 0-2 of `solved` (or 3-5), the pieces moved so their means lie at `centre`.
    auto assemble = [&](const Eigen::MatrixXd& solved, int column,
                        const std::vector<Eigen::Vector3d>& centre, std::vector<Vec3d>& dest) {
        std::vector<Eigen::Vector3d> y(n, Eigen::Vector3d::Zero());
        std::vector<Eigen::Vector3d> mean(mPieceSize.size(), Eigen::Vector3d::Zero());
        for (size_t v = 0; v < n; ++v) {
            if (mFree[v] >= 0) y[v] = solved.block<1, 3>(mFree[v], column).transpose();
            mean[mPiece[v]] += y[v];
        }
        dest.resize(n);
        for (size_t v = 0; v < n; ++v) {
            const uint32_t p = mPiece[v];
            const Eigen::Vector3d x = y[v] + centre[p] - mean[p] / mPieceSize[p];
            dest[v] = Vec3d(x.x(), x.y(), x.z());
        }
    };
    Eigen::MatrixXd rhs;
    rightHandSide(times, rhs);
    // The six columns are independent solves with one factor (read-only): one per task.
    Eigen::MatrixXd solved = rhs;
    if (mRows)
        tbb::parallel_for(0, 6, [&](int c) {
            const Eigen::VectorXd column = rhs.col(c);
            solved.col(c) = mSolver.solve(column);
        });
    assemble(solved, 0, times.centre, out);
    assemble(solved, 3, times.drift, velocity);
}

} // namespace volmorph::detail
