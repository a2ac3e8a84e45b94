#include "blend/variational/Interpolant.h"

#include <Eigen/LU>
#include <Eigen/QR>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace volmorph::detail::variational {

uint64_t denseSolveBytes(size_t count)
{
    const uint64_t n = uint64_t(count) + 5;
    return 2 * n * n * sizeof(double); // the matrix, and the LU factors Eigen keeps
}

Interpolant Interpolant::solveDense(const std::vector<Constraint>& constraints)
{
    const Eigen::Index n = Eigen::Index(constraints.size());
    if (n < 5) throw std::invalid_argument("a variational function needs at least 5 constraints");
    Eigen::MatrixXd system = Eigen::MatrixXd::Zero(n + 5, n + 5);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 5);
    for (Eigen::Index i = 0; i < n; ++i) {
        const Point4& ci = constraints[size_t(i)].point;
        for (Eigen::Index j = 0; j < i; ++j) {
            const double r = (ci - constraints[size_t(j)].point).norm();
            system(i, j) = system(j, i) = r * r * r;
        }
        system(i, n) = system(n, i) = 1.0;
        for (int k = 0; k < 4; ++k) system(i, n + 1 + k) = system(n + 1 + k, i) = ci[k];
        rhs[i] = constraints[size_t(i)].value;
    }
    // The polynomial is determined when the points span the 4 dimensions (P has rank 5); r^3's
    // matrix is then conditionally positive definite on P's null space and the system regular.
    if (Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(system.topRightCorner(n, 5)).rank() < 5)
        throw std::invalid_argument("the constraints do not determine a variational function: "
                                    "they lie in one hyperplane of (x, y, z, t)");
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(system);
    const Eigen::VectorXd solution = lu.solve(rhs);
    const double residual = (system * solution - rhs).norm();
    if (!std::isfinite(residual) || residual > 1e-6 * (1.0 + rhs.norm()))
        throw std::invalid_argument("the variational system could not be solved (residual " +
                                    std::to_string(residual) + ")");
    std::vector<Point4> centres;
    centres.reserve(size_t(n));
    for (const Constraint& c : constraints) centres.push_back(c.point);
    return Interpolant(std::move(centres), solution.head(n), solution.tail<5>());
}

Interpolant::Interpolant(std::vector<Point4> centres, Eigen::VectorXd weights,
                         Eigen::Matrix<double, 5, 1> polynomial)
    : mCentres(4, Eigen::Index(centres.size())), mWeights(std::move(weights)),
      mPolynomial(polynomial)
{
    if (Eigen::Index(centres.size()) != mWeights.size())
        throw std::invalid_argument("an interpolant needs one weight per centre");
    for (size_t j = 0; j < centres.size(); ++j) mCentres.col(Eigen::Index(j)) = centres[j].array();
}

double Interpolant::operator()(const Point4& x) const
{
    const Eigen::ArrayXd r = (mCentres.colwise() - x.array()).square().colwise().sum().sqrt();
    return mPolynomial[0] + mPolynomial.tail<4>().dot(x) + (mWeights.array() * r.cube()).sum();
}

Point4 Interpolant::gradient(const Point4& x) const
{
    // d(r^3)/dx = 3 r (x - c): smooth, zero at the centre.
    const Eigen::Array<double, 4, Eigen::Dynamic> d = mCentres.colwise() - x.array();
    const Eigen::ArrayXd scale =
        3.0 * mWeights.array() * d.square().colwise().sum().sqrt().transpose();
    return mPolynomial.tail<4>() - (d.rowwise() * scale.transpose()).rowwise().sum().matrix();
}

} // namespace volmorph::detail::variational
