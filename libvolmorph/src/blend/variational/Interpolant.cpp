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
    : mCentres(std::move(centres)), mWeights(std::move(weights)), mPolynomial(polynomial)
{
    if (Eigen::Index(mCentres.size()) != mWeights.size())
        throw std::invalid_argument("an interpolant needs one weight per centre");
}

double Interpolant::operator()(const Point4& x) const
{
    double f = mPolynomial[0] + mPolynomial.tail<4>().dot(x);
    for (size_t j = 0; j < mCentres.size(); ++j) {
        const double r = (x - mCentres[j]).norm();
        f += mWeights[Eigen::Index(j)] * r * r * r;
    }
    return f;
}

Point4 Interpolant::gradient(const Point4& x) const
{
    // d(r^3)/dx = 3 r (x - c): smooth, zero at the centre.
    Point4 g = mPolynomial.tail<4>();
    for (size_t j = 0; j < mCentres.size(); ++j) {
        const Point4 d = x - mCentres[j];
        g += (3.0 * mWeights[Eigen::Index(j)] * d.norm()) * d;
    }
    return g;
}

} // namespace volmorph::detail::variational
