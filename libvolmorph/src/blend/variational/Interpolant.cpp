#include "blend/variational/Interpolant.h"

#include <Eigen/LU>
#include <Eigen/QR>

#include <cmath>
#include <immintrin.h>
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
    const size_t padded = (centres.size() + 3) & ~size_t(3);
    for (int k = 0; k < 4; ++k) {
        mCentres[size_t(k)].assign(padded, 0.0);
        for (size_t j = 0; j < centres.size(); ++j) mCentres[size_t(k)][j] = centres[j][k];
    }
    mPaddedWeights.assign(padded, 0.0);
    for (size_t j = 0; j < centres.size(); ++j) mPaddedWeights[j] = mWeights[Eigen::Index(j)];
}

std::pair<Interpolant, Interpolant> Interpolant::splitByTime(double w, double reach) const
{
    std::vector<Point4> centres[2];
    std::vector<double> weights[2];
    for (size_t j = 0; j < size(); ++j) {
        const Point4 c(mCentres[0][j], mCentres[1][j], mCentres[2][j], mCentres[3][j]);
        const int far = std::abs(c[3] - w) >= reach ? 1 : 0;
        centres[far].push_back(c);
        weights[far].push_back(mWeights[Eigen::Index(j)]);
    }
    const auto make = [&](int k, const Eigen::Matrix<double, 5, 1>& polynomial) {
        return Interpolant(
            std::move(centres[k]),
            Eigen::Map<const Eigen::VectorXd>(weights[k].data(), Eigen::Index(weights[k].size())),
            polynomial);
    };
    return {make(0, Eigen::Matrix<double, 5, 1>::Zero()), make(1, mPolynomial)};
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

/// What the sums take: f alone, f and df/dt' (sums[4] only), or f and its whole gradient.
enum Wanted { kValue, kRate, kGradient };

/// The sums over the centres of w r^3 (sums[0]) and of 3 w r (x - c) (sums[1..4], as `wanted`
/// says), as four lanes each: centre j goes to lane j % 4. Both builds below add the same
/// numbers in the same order (IEEE operations round lane by lane alike), so every x86-64 machine
/// gets the same bits.
struct Lanes {
    alignas(32) double sums[5][4];
};

/// Four centres a step as two SSE2 halves (every x86-64 has SSE2).
void sumsSse2(const std::array<const double*, 5>& c, size_t n, const double* x, Wanted wanted,
              Lanes& out)
{
    const __m128d x0 = _mm_set1_pd(x[0]), x1 = _mm_set1_pd(x[1]), x2 = _mm_set1_pd(x[2]),
                  x3 = _mm_set1_pd(x[3]), three = _mm_set1_pd(3.0);
    __m128d acc[5][2];
    for (auto& a : acc) a[0] = a[1] = _mm_setzero_pd();
    for (size_t j = 0; j < n; j += 4)
        for (int h = 0; h < 2; ++h) {
            const size_t k = j + 2 * size_t(h);
            const __m128d d0 = _mm_sub_pd(x0, _mm_loadu_pd(c[0] + k)),
                          d1 = _mm_sub_pd(x1, _mm_loadu_pd(c[1] + k)),
                          d2 = _mm_sub_pd(x2, _mm_loadu_pd(c[2] + k)),
                          d3 = _mm_sub_pd(x3, _mm_loadu_pd(c[3] + k));
            const __m128d r2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(d0, d0), _mm_mul_pd(d1, d1)),
                                          _mm_add_pd(_mm_mul_pd(d2, d2), _mm_mul_pd(d3, d3)));
            const __m128d wr = _mm_mul_pd(_mm_loadu_pd(c[4] + k), _mm_sqrt_pd(r2));
            acc[0][h] = _mm_add_pd(acc[0][h], _mm_mul_pd(wr, r2));
            if (wanted == kValue) continue;
            const __m128d s = _mm_mul_pd(three, wr);
            acc[4][h] = _mm_add_pd(acc[4][h], _mm_mul_pd(s, d3));
            if (wanted == kRate) continue;
            acc[1][h] = _mm_add_pd(acc[1][h], _mm_mul_pd(s, d0));
            acc[2][h] = _mm_add_pd(acc[2][h], _mm_mul_pd(s, d1));
            acc[3][h] = _mm_add_pd(acc[3][h], _mm_mul_pd(s, d2));
        }
    for (int i = 0; i < 5; ++i) {
        _mm_store_pd(out.sums[i], acc[i][0]);
        _mm_store_pd(out.sums[i] + 2, acc[i][1]);
    }
}

/// The same with AVX2's four lanes (no FMA: the same roundings).
__attribute__((target("avx2"))) void sumsAvx2(const std::array<const double*, 5>& c, size_t n,
                                              const double* x, Wanted wanted, Lanes& out)
{
    const __m256d x0 = _mm256_set1_pd(x[0]), x1 = _mm256_set1_pd(x[1]), x2 = _mm256_set1_pd(x[2]),
                  x3 = _mm256_set1_pd(x[3]), three = _mm256_set1_pd(3.0);
    __m256d acc[5];
    for (auto& a : acc) a = _mm256_setzero_pd();
    for (size_t j = 0; j < n; j += 4) {
        const __m256d d0 = _mm256_sub_pd(x0, _mm256_loadu_pd(c[0] + j)),
                      d1 = _mm256_sub_pd(x1, _mm256_loadu_pd(c[1] + j)),
                      d2 = _mm256_sub_pd(x2, _mm256_loadu_pd(c[2] + j)),
                      d3 = _mm256_sub_pd(x3, _mm256_loadu_pd(c[3] + j));
        const __m256d r2 =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d0, d0), _mm256_mul_pd(d1, d1)),
                          _mm256_add_pd(_mm256_mul_pd(d2, d2), _mm256_mul_pd(d3, d3)));
        const __m256d wr = _mm256_mul_pd(_mm256_loadu_pd(c[4] + j), _mm256_sqrt_pd(r2));
        acc[0] = _mm256_add_pd(acc[0], _mm256_mul_pd(wr, r2));
        if (wanted == kValue) continue;
        const __m256d s = _mm256_mul_pd(three, wr);
        acc[4] = _mm256_add_pd(acc[4], _mm256_mul_pd(s, d3));
        if (wanted == kRate) continue;
        acc[1] = _mm256_add_pd(acc[1], _mm256_mul_pd(s, d0));
        acc[2] = _mm256_add_pd(acc[2], _mm256_mul_pd(s, d1));
        acc[3] = _mm256_add_pd(acc[3], _mm256_mul_pd(s, d2));
    }
    for (int i = 0; i < 5; ++i) _mm256_store_pd(out.sums[i], acc[i]);
}

const bool kAvx2 = __builtin_cpu_supports("avx2");

double sumLanes(const double* lanes)
{
    return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

} // namespace

double Interpolant::evaluate(const Point4& x, Point4* gradient) const
{
    return sum(x, gradient, nullptr, kAvx2);
}

double Interpolant::evaluateWithRate(const Point4& x, double* rate) const
{
    return sum(x, nullptr, rate, kAvx2);
}

double Interpolant::evaluateBaseline(const Point4& x, Point4* gradient) const
{
    return sum(x, gradient, nullptr, false);
}

double Interpolant::sum(const Point4& x, Point4* gradient, double* rate, bool avx2) const
{
    // The frame's hottest loop: four centres a step (sumsSse2, sumsAvx2), d(r^3)/dx = 3 r (x - c).
    const std::array<const double*, 5> c{mCentres[0].data(), mCentres[1].data(), mCentres[2].data(),
                                         mCentres[3].data(), mPaddedWeights.data()};
    Lanes lanes;
    const Wanted wanted = gradient ? kGradient : rate ? kRate : kValue;
    (avx2 ? sumsAvx2 : sumsSse2)(c, mPaddedWeights.size(), x.data(), wanted, lanes);
    if (gradient)
        *gradient =
            mPolynomial.tail<4>() + Point4(sumLanes(lanes.sums[1]), sumLanes(lanes.sums[2]),
                                           sumLanes(lanes.sums[3]), sumLanes(lanes.sums[4]));
    if (rate) *rate = mPolynomial[4] + sumLanes(lanes.sums[4]);
    return mPolynomial[0] + mPolynomial.tail<4>().dot(x) + sumLanes(lanes.sums[0]);
}

} // namespace volmorph::detail::variational
