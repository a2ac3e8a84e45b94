// Turk and O'Brien's variational implicit function ("Shape Transformation Using Variational
// Implicit Functions", SIGGRAPH 1999), the core of blend.mode = "variational" (issue 40):
//
//   f(x) = sum_j w_j phi(|x - c_j|) + p0 + p . x,   phi(r) = r^3,
//
// in four dimensions, x = (x, y, z, t * time_scale) (world units), through constraints
// f(c_i) = h_i, with the side conditions sum_j w_j = 0 and sum_j w_j c_j = 0 that make f the
// smoothest interpolant (the 3D paper's basis and polynomial, used in 4D as the paper does for
// shape transformation). The system
//
//   [ A   P ] [w]   [h]        A_ij = phi(|c_i - c_j|),  P_i = [1, c_i],
//   [ P^T 0 ] [p] = [0],
//
// is dense and symmetric indefinite. solveDense() is the reference: Eigen's LU with partial
// pivoting, O(N^3) time and (N + 5)^2 doubles.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace volmorph::detail::variational {

using Point4 = Eigen::Vector4d;

/// f(point) = value.
struct Constraint {
    Point4 point;
    double value = 0.0;
};

/// The bytes solveDense() holds for `count` constraints: the matrix and its LU factors.
uint64_t denseSolveBytes(size_t count);

class Interpolant {
public:
    Interpolant() = default;

    /// The interpolant through `constraints` by a dense LU solve. Throws std::invalid_argument
    /// when fewer than 5 are given or they do not determine it (all in one hyperplane: the
    /// polynomial is then not unique).
    static Interpolant solveDense(const std::vector<Constraint>& constraints);

    /// From centres, their weights and the polynomial (p0, px, py, pz, pt): what another solver
    /// of the same system produces.
    Interpolant(std::vector<Point4> centres, Eigen::VectorXd weights,
                Eigen::Matrix<double, 5, 1> polynomial);

    double operator()(const Point4& x) const;
    /// (df/dx, df/dy, df/dz, df/dt'), t' = t * time_scale.
    Point4 gradient(const Point4& x) const;
    /// f(x), and its gradient into `gradient` when not null: one pass for both, with AVX2 where
    /// the machine has it.
    double evaluate(const Point4& x, Point4* gradient) const;
    /// f(x), and df/dt' into `rate` when not null (the gradient's last component, the same bits,
    /// for a fifth of the gradient's extra sums).
    double evaluateWithRate(const Point4& x, double* rate) const;
    /// The same through the SSE2 build alone: the test that both give the same bits calls it.
    double evaluateBaseline(const Point4& x, Point4* gradient) const;

    /// The centres within `reach` of `w` along t' (and their weights), and the others with the
    /// polynomial: two interpolants whose sum is this one.
    std::pair<Interpolant, Interpolant> splitByTime(double w, double reach) const;

    size_t size() const { return size_t(mWeights.size()); }
    const Eigen::VectorXd& weights() const { return mWeights; }
    const Eigen::Matrix<double, 5, 1>& polynomial() const { return mPolynomial; }

private:
    double sum(const Point4& x, Point4* gradient, double* rate, bool avx2) const;

    /// The centres by coordinate (x, y, z, t'), and the weights again beside them, each padded to
    /// a multiple of 4 (a zero weight) for the four-lane loop.
    std::array<std::vector<double>, 4> mCentres;
    std::vector<double> mPaddedWeights;
    Eigen::VectorXd mWeights;
    Eigen::Matrix<double, 5, 1> mPolynomial = Eigen::Matrix<double, 5, 1>::Zero();
};

} // namespace volmorph::detail::variational
