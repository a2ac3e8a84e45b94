// As-rigid-as-possible in-betweens of two meshes of one connectivity (Alexa, Cohen-Or and Levin
// 2000; for surfaces, Xu et al. 2005 "Poisson shape interpolation").
//
// Each triangle's affine map A from its source to its target shape (the triangle's two edges and
// a normal scaled by the square root of its double area, as in Sumner and Popovic 2004) is split
// A = R S by the polar decomposition; at tau the triangle asks for G(tau) = R(tau) ((1 - tau) I +
// tau S), where R(tau) turns by tau times R's angle about R's axis. The vertices x are those whose
// edges e' best match G e over every triangle, in the sense of the gradient energy
//   E(x) = sum over triangles T, edges e = (a, b) of T of  cot(angle opposite e) / 2 *
//          | (x_a - x_b) - G_T(tau) (p_a - p_b) |^2,
// which is the integral of | grad x - G |^2 over the surface: its matrix is the source's
// cotangent Laplacian, the same at every tau, factored once (one vertex per connected piece held
// at the origin); each piece is then moved so that its vertex mean follows the straight line
// between the two sides' means. At tau = 0 and 1 every G maps the source's edges onto that side's
// exactly, so the ends are the inputs. A limb that turns by theta keeps its thickness, where the
// straight line shrinks it by cos(theta / 2) half-way.
//
// The Laplacian's weights come from intrinsically mollified edge lengths (Cotangent.h), so that the
// slivers of a merged mesh do not make it ill-conditioned; whatever the fit misses of the inputs at
// tau = 0 and 1 (rounding, triangles too thin to have a frame) is taken out along the straight
// line, so the ends are the inputs exactly.
//
// The velocity is exact: dG/dtau = theta [k]x R(tau) S(tau) + R(tau) (S - I) gives the right-hand
// side's derivative, and the same factorization solves for dx/dtau.
#pragma once

#include <volmorph/Mesh.h>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>

#include <vector>

namespace volmorph::detail {

class RigidInterpolation {
public:
    /// `source` and `target` are the positions of one connectivity, `triangles` (world units).
    /// Throws std::runtime_error when the Laplacian cannot be factored (a mesh made of degenerate
    /// triangles only).
    RigidInterpolation(const std::vector<Vec3d>& source, const std::vector<Vec3d>& target,
                       const std::vector<Vec3I>& triangles);

    /// Positions at `tau` and d position / d tau (one solve for both).
    void positions(double tau, std::vector<Vec3d>& out, std::vector<Vec3d>& velocity) const;
    /// Positions with each vertex at its own tau (under a timing) and d position / d t, from each
    /// vertex's d tau / d t (`vertexRate`): each triangle asks for G at its corners' mean tau, and
    /// each piece's vertex mean follows the mean of its vertices' straight lines, each at its own
    /// tau. With every tau equal and every rate 1, what positions(tau) gives.
    void positions(const std::vector<double>& vertexTau, const std::vector<double>& vertexRate,
                   std::vector<Vec3d>& out, std::vector<Vec3d>& velocity) const;

    /// One triangle's map from source to target, A = rotation * stretch.
    struct Triangle {
        Eigen::Matrix3d rotation, stretch; ///< A = rotation * stretch
        Eigen::Vector3d axis;              ///< of the rotation, unit
        double angle = 0.0;                ///< of the rotation, radians in [0, pi]
    };

private:
    struct Edge {
        uint32_t a, b, triangle;
        double weight;        ///< cot(opposite angle) / 2
        Eigen::Vector3d edge; ///< source p_a - p_b
    };
    /// Each triangle's tau and d tau / d t (or 1: the derivative along tau), and each piece's
    /// vertex mean and its rate.
    struct Times {
        std::vector<double> tau, rate;
        std::vector<Eigen::Vector3d> centre, drift;
    };
    void findPieces(const std::vector<Vec3d>& source, const std::vector<Vec3d>& target,
                    const std::vector<Vec3I>& triangles);
    /// The fit at `times` (or everywhere at tau), before the ends' misses are taken out.
    void solve(const Times& times, std::vector<Vec3d>& out, std::vector<Vec3d>& velocity) const;
    void solveAt(double tau, std::vector<Vec3d>& out, std::vector<Vec3d>& velocity) const;
    /// The reduced system's right-hand sides: columns 0-2 for the positions, 3-5 for their
    /// derivative.
    void rightHandSide(const Times& times, Eigen::MatrixXd& rhs) const;

    std::vector<Triangle> mTriangles;
    std::vector<Edge> mEdges;
    int mRows = 0;                ///< of the reduced system: the vertices not held
    std::vector<int> mFree;       ///< vertex -> row of the reduced system, -1 for a held vertex
    std::vector<uint32_t> mPiece; ///< vertex -> its connected piece
    std::vector<Eigen::Vector3d> mSourceMean, mTargetMean; ///< per piece
    std::vector<double> mPieceSize;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> mSolver;
    std::vector<Vec3d> mMissed0, mMissed1; ///< the fit's positions minus the inputs at 0 and 1
    std::vector<Vec3d> mSource, mTarget;   ///< the inputs (each vertex's straight line)
    std::vector<Vec3I> mCorners;           ///< the triangles
};

} // namespace volmorph::detail
