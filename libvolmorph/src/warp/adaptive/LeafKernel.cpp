#include "warp/adaptive/LeafKernel.h"

#include "warp/adaptive/Simd.h"

#include <cmath>

namespace volmorph::detail {
namespace {

/// A row function at the first row of slice i; each next row of the slice adds dy.
VOLMORPH_ALWAYS_INLINE inline v8f first(const RowAffine& f, int i)
{
    return f.start[i] + kZ * f.dz;
}

/// Distance in the element's frame at a row's 8 voxels, per type.
template <FeatureType T>
VOLMORPH_ALWAYS_INLINE inline v8f frameDistance(v8f qx, v8f qy, v8f qz, float hx, float hy,
                                                float hz)
{
    if constexpr (T == FeatureType::Point) return vsqrt(qx * qx + qy * qy + qz * qz);
    if constexpr (T == FeatureType::Segment) {
        const v8f a = outside(qx, splat8(hx));
        return vsqrt(a * a + qy * qy + qz * qz);
    }
    if constexpr (T == FeatureType::Rectangle) {
        const v8f a = outside(qx, splat8(hx)), b = outside(qy, splat8(hy));
        return vsqrt(a * a + b * b + qz * qz);
    }
    const v8f a = outside(qx, splat8(hx)), b = outside(qy, splat8(hy)), c = outside(qz, splat8(hz));
    return vsqrt(a * a + b * b + c * c);
}

/// The far sums of channel c along the rows of slice i: the first row's (y = 0) and the step to
/// the next row, from the leaf's x edges (per channel, (y, z) = (0, 0), (8, 0), (0, 8), (8, 8)).
VOLMORPH_ALWAYS_INLINE inline void farRows(const float edge[4][8], int i, v8f& row0, v8f& dy)
{
    const v8f fraction = kZ * 0.125f; // k / 8
    row0 = edge[0][i] + fraction * (edge[2][i] - edge[0][i]);
    const v8f row8 = edge[1][i] + fraction * (edge[3][i] - edge[1][i]);
    dy = (row8 - row0) * 0.125f;
}

/// Row r's points from its residual sums and the reciprocal of its weight sum: p = B + sum /
/// weight. (The slices' reciprocals are taken first, all 8 rows', for the reason given at
/// addNearPairs.)
VOLMORPH_ALWAYS_INLINE inline void storeRow(WarpLeaf& leaf, int r, const v8f base[6],
                                            const v8f acc[7], v8f inv)
{
    for (int c = 0; c < 3; ++c) {
        store8(leaf.s[c] + 8 * r, base[c] + acc[1 + c] * inv);
        store8(leaf.t[c] + 8 * r, base[3 + c] + acc[4 + c] * inv);
    }
}

/// Adds the near pairs of type T, [begin, end), at every row r: weight into sums[r][0], weighted
/// residuals into sums[r][1..6] (source x, y, z, target x, y, z). Pair by pair and slice by slice,
/// in two passes over the slice's 8 rows: first their weights, then the sums. The weights' square
/// roots and divisions are long-latency and independent from row to row; done first, they overlap,
/// where one pass per row would fill the scheduler with the sums waiting on each row's division.
/// (Each value takes the same operations in the same order either way, so the bits are the same.)
template <FeatureType T, bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void addNearPairs(const LeafJob& job, size_t begin, size_t end,
                                                v8f sums[64][7])
{
    const float off = float(job.offset);
    for (size_t p = begin; p < end; ++p) {
        const NearRows& n = job.rows[p];
        for (int i = 0; i < 8; ++i) {
            v8f w[8];
            {
                v8f q[3];
                for (int c = 0; c < 3; ++c) q[c] = first(n.f[c], i);
                for (int j = 0; j < 8; ++j) {
                    const v8f d =
                        off + frameDistance<T>(q[0], q[1], q[2], n.half[0], n.half[1], n.half[2]);
                    if constexpr (InverseSquare) {
                        w[j] = 1.0f / (d * d);
                    } else {
                        for (int l = 0; l < 8; ++l)
                            w[j][l] =
                                float(double(n.scale) * std::pow(double(d[l]), -job.exponent));
                    }
                    for (int c = 0; c < 3; ++c) q[c] += n.f[c].dy;
                }
            }
            v8f r[6];
            for (int c = 0; c < 6; ++c) r[c] = first(n.f[3 + c], i);
            for (int j = 0; j < 8; ++j) {
                v8f* acc = sums[8 * i + j];
                acc[0] += w[j];
                for (int c = 0; c < 6; ++c) acc[1 + c] += w[j] * r[c];
                for (int c = 0; c < 6; ++c) r[c] += n.f[3 + c].dy;
            }
        }
    }
}

/// Per near pair: its weight w and w R (R = A - B) at the corners, taken off the exact sums there,
/// in double, 4 corners at a time (z = 0, then z = 8): what remains are the far sums.
template <bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void takeOffCorners(LeafJob& job, const NearTerm& t, const Vec3d& q0)
{
    const v4d cx = {0, 8, 0, 8}, cy = {0, 0, 8, 8};
    const Feature& e = *t.element;
    const Vec3d* axes[3] = {&e.x, &e.y, &e.z};
    for (int m = 0; m < 2; ++m) {
        const double cz = 8.0 * m;
        v4d out2 = splat(0.0);
        for (int k = 0; k < 3; ++k) {
            const Vec3d& a = *axes[k];
            const v4d q = q0[k] + cx * a.x() + cy * a.y() + cz * a.z();
            const v4d d = outside(q, splat(t.half[k]));
            out2 += d * d;
        }
        const v4d r = job.offset + vsqrt(out2);
        v4d w;
        if constexpr (InverseSquare) {
            w = 1.0 / (r * r);
        } else {
            for (int l = 0; l < 4; ++l) w[l] = t.scale * std::pow(r[l], -job.exponent);
        }
        double* far0 = job.far[0] + 4 * m;
        store4(far0, load4(far0) - w);
        for (int c = 0; c < 3; ++c) {
            const v4d rs = t.rs[c] + cx * t.drs[0][c] + cy * t.drs[1][c] + cz * t.drs[2][c];
            const v4d rt = t.rt[c] + cx * t.drt[0][c] + cy * t.drt[1][c] + cz * t.drt[2][c];
            double* fs = job.far[1 + c] + 4 * m;
            double* ft = job.far[4 + c] + 4 * m;
            store4(fs, load4(fs) - w * rs);
            store4(ft, load4(ft) - w * rt);
        }
    }
}

/// Each near pair taken off the corners' sums, and its frame coordinates and residuals at each
/// row's first voxel, with their steps, into job.rows.
template <bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void prepareNearPairs(LeafJob& job)
{
    job.rows.resize(job.near.size());
    for (size_t p = 0; p < job.near.size(); ++p) {
        const NearTerm& t = job.near[p];
        const Feature& e = *t.element;
        const Vec3d q0 = e.frameCoordinates(job.origin);
        takeOffCorners<InverseSquare>(job, t, q0);
        NearRows& n = job.rows[p];
        // Steps of the frame coordinates along x, y and z: the frame's rows.
        const Vec3d dx(e.x.x(), e.y.x(), e.z.x()), dy(e.x.y(), e.y.y(), e.z.y()),
            dz(e.x.z(), e.y.z(), e.z.z());
        for (int c = 0; c < 3; ++c) {
            n.f[c].set(q0[c], dx[c], dy[c], dz[c]);
            n.f[3 + c].set(t.rs[c], t.drs[0][c], t.drs[1][c], t.drs[2][c]);
            n.f[6 + c].set(t.rt[c], t.drt[0][c], t.drt[1][c], t.drt[2][c]);
            n.half[c] = float(0.5 * e.scale[c]);
        }
        n.scale = float(t.scale);
    }
}

/// The far sums along x on the leaf's four edges (lanes i), per channel, in single precision:
/// edge[c][m] for (y, z) = (0, 0), (8, 0), (0, 8), (8, 8).
VOLMORPH_ALWAYS_INLINE inline void farEdges(const LeafJob& job, float edge[7][4][8])
{
    const v8f fraction = kZ * 0.125f; // i / 8
    for (int c = 0; c < 7; ++c) {
        const double* v = job.far[c];
        for (int m = 0; m < 4; ++m) {
            const float a = float(v[2 * m]), b = float(v[2 * m + 1]);
            store8(edge[c][m], a + fraction * (b - a));
        }
    }
}

/// Every pair far: the rows' sums go straight into the points (storeRow, as fillWithNear does,
/// without storing the sums first).
VOLMORPH_ALWAYS_INLINE inline void fillAllFar(const float edge[7][4][8], const RowAffine b[6],
                                              WarpLeaf& leaf)
{
    for (int i = 0; i < 8; ++i) {
        v8f row[7], dy[7], base[6], inv[8];
        for (int c = 0; c < 7; ++c) farRows(edge[c], i, row[c], dy[c]);
        for (int c = 0; c < 6; ++c) base[c] = first(b[c], i);
        v8f weight = row[0];
        for (int j = 0; j < 8; ++j) {
            inv[j] = 1.0f / weight;
            weight += dy[0];
        }
        for (int j = 0; j < 8; ++j) {
            storeRow(leaf, 8 * i + j, base, row, inv[j]);
            for (int c = 1; c < 7; ++c) row[c] += dy[c];
            for (int c = 0; c < 6; ++c) base[c] += b[c].dy;
        }
    }
}

/// The far sums of every row stored, the near pairs added over all rows, then the points.
template <bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void fillWithNear(const LeafJob& job, const float edge[7][4][8],
                                                const RowAffine b[6], WarpLeaf& leaf)
{
    alignas(32) v8f sums[64][7];
    for (int c = 0; c < 7; ++c)
        for (int i = 0; i < 8; ++i) {
            v8f row, dy;
            farRows(edge[c], i, row, dy);
            for (int j = 0; j < 8; ++j) {
                sums[8 * i + j][c] = row;
                row += dy;
            }
        }
    addNearPairs<FeatureType::Point, InverseSquare>(job, 0, job.typeEnd[0], sums);
    addNearPairs<FeatureType::Segment, InverseSquare>(job, job.typeEnd[0], job.typeEnd[1], sums);
    addNearPairs<FeatureType::Rectangle, InverseSquare>(job, job.typeEnd[1], job.typeEnd[2], sums);
    addNearPairs<FeatureType::Box, InverseSquare>(job, job.typeEnd[2], job.typeEnd[3], sums);
    for (int i = 0; i < 8; ++i) {
        v8f base[6], inv[8];
        for (int c = 0; c < 6; ++c) base[c] = first(b[c], i);
        for (int j = 0; j < 8; ++j) inv[j] = 1.0f / sums[8 * i + j][0];
        for (int j = 0; j < 8; ++j) {
            storeRow(leaf, 8 * i + j, base, sums[8 * i + j], inv[j]);
            for (int c = 0; c < 6; ++c) base[c] += b[c].dy;
        }
    }
}

/// Fills a leaf by rows of 8 voxels along z: the far sums interpolated trilinearly (along x on
/// the leaf's edges, then per slice i its first and last rows (y = 0 and y = 8) along z, and the
/// rows between one step along y apart: farRows), the near pairs added pair by pair over all
/// rows, then p = B(x) + residual sum / weight sum, all in single precision as the points are
/// stored (its rounding, some 1e-5 voxel at hundreds of voxels from the origin, is far below a
/// tolerance).
template <bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void fillLeafBody(LeafJob& job, WarpLeaf& leaf)
{
    prepareNearPairs<InverseSquare>(job);
    alignas(32) float edge[7][4][8];
    farEdges(job, edge);
    // p = B + residual sum / weight sum, B walked like the near pairs' functions.
    RowAffine b[6];
    const Vec3d bs0 = job.bS.apply(job.origin), bt0 = job.bT.apply(job.origin);
    for (int c = 0; c < 3; ++c) {
        b[c].set(bs0[c], job.bS.col[0][c], job.bS.col[1][c], job.bS.col[2][c]);
        b[3 + c].set(bt0[c], job.bT.col[0][c], job.bT.col[1][c], job.bT.col[2][c]);
    }
    if (job.near.empty())
        fillAllFar(edge, b, leaf);
    else
        fillWithNear<InverseSquare>(job, edge, b, leaf);
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 void fillLeafAvx2(LeafJob& job, WarpLeaf& leaf)
{
    if (job.inverseSquare)
        fillLeafBody<true>(job, leaf);
    else
        fillLeafBody<false>(job, leaf);
}
VOLMORPH_AVX512 void fillLeafAvx512(LeafJob& job, WarpLeaf& leaf)
{
    if (job.inverseSquare)
        fillLeafBody<true>(job, leaf);
    else
        fillLeafBody<false>(job, leaf);
}
#endif

void fillLeafBaseline(LeafJob& job, WarpLeaf& leaf)
{
    if (job.inverseSquare)
        fillLeafBody<true>(job, leaf);
    else
        fillLeafBody<false>(job, leaf);
}

/// The box of a leaf's warped points on each side (0 source, 1 target), 8 lanes at a time.
VOLMORPH_ALWAYS_INLINE inline void leafRangeBody(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2])
{
    for (int side = 0; side < 2; ++side)
        for (int c = 0; c < 3; ++c) {
            const float* v = side == 0 ? leaf.s[c] : leaf.t[c];
            v8f l = load8(v), u = l;
            for (int m = 8; m < 512; m += 8) {
                const v8f x = load8(v + m);
                l = x < l ? x : l;
                u = x > u ? x : u;
            }
            float a = l[0], b = u[0];
            for (int z = 1; z < 8; ++z) {
                a = std::min(a, l[z]);
                b = std::max(b, u[z]);
            }
            lo[side][c] = a;
            hi[side][c] = b;
        }
}

void leafRangeBaseline(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2])
{
    leafRangeBody(leaf, lo, hi);
}
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 void leafRangeAvx2(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2])
{
    leafRangeBody(leaf, lo, hi);
}
VOLMORPH_AVX512 void leafRangeAvx512(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2])
{
    leafRangeBody(leaf, lo, hi);
}
#endif

} // namespace

void fillLeaf(LeafJob& job, WarpLeaf& leaf, KernelBuild build)
{
    pickBuild(build, VOLMORPH_BUILDS(fillLeaf))(job, leaf);
}

void leafRange(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2], KernelBuild build)
{
    pickBuild(build, VOLMORPH_BUILDS(leafRange))(leaf, lo, hi);
}

/// The most capable of the kernels' builds this CPU runs (AdaptiveWarp.h; every kernel picks by
/// it).
KernelBuild bestKernelBuild()
{
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
    static const KernelBuild best =
        __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw")
            ? KernelBuild::Avx512
        : __builtin_cpu_supports("avx2") ? KernelBuild::Avx2
                                         : KernelBuild::Baseline;
    return best;
#else
    return KernelBuild::Baseline;
#endif
}

} // namespace volmorph::detail
