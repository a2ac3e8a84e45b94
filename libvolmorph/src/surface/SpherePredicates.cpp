#include "SpherePredicates.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace volmorph::detail {
namespace {

using Wide = __int128;

int sign(Wide v)
{
    return (v > 0) - (v < 0);
}

Wide det3(const int64_t (&m)[3][3])
{
    return Wide(m[0][0]) * (Wide(m[1][1]) * m[2][2] - Wide(m[1][2]) * m[2][1]) -
           Wide(m[0][1]) * (Wide(m[1][0]) * m[2][2] - Wide(m[1][2]) * m[2][0]) +
           Wide(m[0][2]) * (Wide(m[1][0]) * m[2][1] - Wide(m[1][1]) * m[2][0]);
}

/// The coefficient of the perturbation term that moves the entries in `mask` (bit 3 row + column):
/// the sum over the permutations through those entries of sign(permutation) times the product of
/// the entries the permutation takes from the other rows.
Wide coefficient(const int64_t (&m)[3][3], unsigned mask)
{
    static constexpr int kPerms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                         {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    Wide sum = 0;
    for (int p = 0; p < 6; ++p) {
        bool through = true;
        for (int bit = 0; bit < 9 && through; ++bit)
            if ((mask >> bit & 1u) && kPerms[p][bit / 3] != bit % 3) through = false;
        if (!through) continue;
        Wide term = p < 3 ? 1 : -1;
        for (int r = 0; r < 3; ++r)
            if (!(mask >> (3 * r + kPerms[p][r]) & 1u)) term *= m[r][kPerms[p][r]];
        sum += term;
    }
    return sum;
}

} // namespace

GridDirection toGrid(const Vec3d& unit)
{
    return {std::llround(unit.x() * kGridScale), std::llround(unit.y() * kGridScale),
            std::llround(unit.z() * kGridScale)};
}

Vec3d fromGrid(const GridDirection& g)
{
    const Vec3d v(double(g.x), double(g.y), double(g.z));
    return v / v.length();
}

int orientation(const GridDirection& p, const GridDirection& q, const GridDirection& r)
{
    const int64_t m[3][3] = {{p.x, p.y, p.z}, {q.x, q.y, q.z}, {r.x, r.y, r.z}};
    return sign(det3(m));
}

int orientationSoS(const GridDirection& p, uint32_t ip, const GridDirection& q, uint32_t iq,
                   const GridDirection& r, uint32_t ir)
{
    if (const int s = orientation(p, q, r); s != 0) return s;
    // Rows in the order of their indices (the earlier point's perturbation is the larger), the
    // determinant's sign flipped once per swap.
    const GridDirection* rows[3] = {&p, &q, &r};
    uint32_t index[3] = {ip, iq, ir};
    int flip = 1;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j + 1 < 3 - i; ++j)
            if (index[j] > index[j + 1]) {
                std::swap(index[j], index[j + 1]);
                std::swap(rows[j], rows[j + 1]);
                flip = -flip;
            }
    const int64_t m[3][3] = {{rows[0]->x, rows[0]->y, rows[0]->z},
                             {rows[1]->x, rows[1]->y, rows[1]->z},
                             {rows[2]->x, rows[2]->y, rows[2]->z}};
    // Entry (row, column) moves by eps^(2^(3 row + column)): the terms in increasing order of the
    // mask are in decreasing order of size, and the full permutations are +-1, so one is not 0.
    for (unsigned mask = 1; mask < 512; ++mask)
        if (const Wide c = coefficient(m, mask); c != 0) return flip * sign(c);
    return flip; // unreachable: the masks of whole permutations have coefficient +-1
}

} // namespace volmorph::detail
