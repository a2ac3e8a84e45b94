#include "blend/variational/Interpolant.h"

#include <Eigen/LU>
#include <Eigen/QR>

#include <cmath>
#include <emmintrin.h>
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
    : mWeights(std::move(weights)), mPolynomial(polynomial)
{
    if (Eigen::Index(centres.size()) != mWeights.size())
        throw std::invalid_argument("an interpolant needs one weight per centre");
    const size_t padded = (centres.size() + 1) & ~size_t(1);
    for (int k = 0; k < 4; ++k) {
        mCentres[size_t(k)].assign(padded, 0.0);
        for (size_t j = 0; j < centres.size(); ++j) mCentres[size_t(k)][j] = centres[j][k];
    }
    mPaddedWeights.assign(padded, 0.0);
    for (size_t j = 0; j < centres.size(); ++j) mPaddedWeights[j] = mWeights[Eigen::Index(j)];
}

double Interpolant::operator()(const Point4& x) const
{
    return evaluate(x, nullptr);
}

Point4 Interpolant::gradient(const Point4& x) const
{
    Point4 g;
    evaluate(x, &g);
    return g;
}

namespace {

double sumLanes(__m128d v)
{
    alignas(16) double lanes[2];
    _mm_store_pd(lanes, v);
    return lanes[0] + lanes[1];
}

} // namespace

double Interpolant::evaluate(const Point4& x, Point4* gradient) const
{
    // Two centres a step with SSE2 (every x86-64 has it, so every machine sums in the same order
    // and gets the same bits): the frame's hottest loop. d(r^3)/dx = 3 r (x - c).
    const double *cx = mCentres[0].data(), *cy = mCentres[1].data(), *cz = mCentres[2].data(),
                 *ct = mCentres[3].data(), *w = mPaddedWeights.data();
    const size_t n = mPaddedWeights.size();
    const __m128d x0 = _mm_set1_pd(x[0]), x1 = _mm_set1_pd(x[1]), x2 = _mm_set1_pd(x[2]),
                  x3 = _mm_set1_pd(x[3]);
    __m128d sum = _mm_setzero_pd();
    __m128d g0 = _mm_setzero_pd(), g1 = g0, g2 = g0, g3 = g0;
    for (size_t j = 0; j < n; j += 2) {
        const __m128d d0 = _mm_sub_pd(x0, _mm_loadu_pd(cx + j)),
                      d1 = _mm_sub_pd(x1, _mm_loadu_pd(cy + j)),
                      d2 = _mm_sub_pd(x2, _mm_loadu_pd(cz + j)),
                      d3 = _mm_sub_pd(x3, _mm_loadu_pd(ct + j));
        const __m128d r2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(d0, d0), _mm_mul_pd(d1, d1)),
                                      _mm_add_pd(_mm_mul_pd(d2, d2), _mm_mul_pd(d3, d3)));
        const __m128d wr = _mm_mul_pd(_mm_loadu_pd(w + j), _mm_sqrt_pd(r2));
        sum = _mm_add_pd(sum, _mm_mul_pd(wr, r2));
        if (!gradient) continue;
        const __m128d s = _mm_mul_pd(_mm_set1_pd(3.0), wr);
        g0 = _mm_add_pd(g0, _mm_mul_pd(s, d0));
        g1 = _mm_add_pd(g1, _mm_mul_pd(s, d1));
        g2 = _mm_add_pd(g2, _mm_mul_pd(s, d2));
        g3 = _mm_add_pd(g3, _mm_mul_pd(s, d3));
    }
    if (gradient)
        *gradient =
            mPolynomial.tail<4>() + Point4(sumLanes(g0), sumLanes(g1), sumLanes(g2), sumLanes(g3));
    return mPolynomial[0] + mPolynomial.tail<4>().dot(x) + sumLanes(sum);
}

} // namespace volmorph::detail::variational
