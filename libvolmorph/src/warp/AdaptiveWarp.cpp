#include "AdaptiveWarp.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace volmorph::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;

/// Trilinear interpolation bounds the error by h^2/8 (|u_xx| + |u_yy| + |u_zz|) (see the header).
/// The bound is a worst case over the leaf; 1 keeps it a bound.
constexpr double kBoundScale = 1.0;

/// Below this offset + distance (index units) the weights are too steep to trust the arithmetic
/// of the sums: the leaf is evaluated exactly (only with a zero or tiny epsilon).
constexpr double kTinyRadius = 1e-6;

/// The per-voxel helpers are inlined into both builds of the leaf kernel (see fillLeaf).
#if defined(__GNUC__)
#define VOLMORPH_ALWAYS_INLINE __attribute__((always_inline))
#else
#define VOLMORPH_ALWAYS_INLINE
#endif

struct LeafJob;

/// Everything the error bound needs of each pair over a cube, one column per quantity (single
/// precision: its rounding, some 1e-7 of each term, is far inside the bound's slack).
/// Stored in groups of 8 pairs, all columns of a group together (one base address for a loop's
/// loads and stores: the columns' own pointers no longer compete for registers).
struct PairBounds {
    enum Column { WMax, W1, W2, Constant, Resid, RS0, RS1, RS2, RT0, RT1, RT2, Term, Hess, Count };
    struct Group {
        float v[Count][8];
    };
    std::vector<Group> groups;
    void resize(size_t padded) { groups.resize(padded / 8); }
    float get(Column c, size_t i) const { return groups[i / 8].v[c][i % 8]; }
};

} // namespace

/// The exact sums at the corners of the candidate leaves: a lattice 8 voxels apart over the
/// leaves' bounding box (index space / 8), evaluated only where a candidate leaf needs it.
/// Left uninitialized until evaluated (only the wanted points are, and only they are read): the
/// whole lattice is allocated per call, and zeroing it cost about 1 ms, serially.
struct alignas(64) AdaptiveWarp::LatticePoint { // one cache line each
    double w;                                   ///< sum w_i
    Vec3d s, t;                                 ///< sum w_i A_i, source and target side
    bool ok;                                    ///< false: on an element with a zero offset
};

struct AdaptiveWarp::Lattice {
    using Point = LatticePoint;
    static_assert(std::is_trivially_default_constructible_v<Point>, "allocated uninitialized");
    Coord lo;  ///< lattice coordinates of point 0 (leaf coordinates)
    Coord dim; ///< points along each axis
    std::unique_ptr<Point[]> points;
    size_t count = 0;
    size_t index(const Coord& leafCoord) const
    {
        const Coord c = leafCoord - lo;
        return (size_t(c.x()) * dim.y() + c.y()) * dim.z() + c.z();
    }
};

namespace {

/// The pairs, one column per quantity, padded to a multiple of 8 (the bound's loops take 8 pairs
/// at a time in single precision, the exact sums 4 at a time in double; padding lanes compute
/// harmless values that are never read, or are masked by `live`). Stored in groups of one
/// vector's lanes, all columns of a group together (see PairBounds).
template <class Real>
struct PairColumns {
    static constexpr size_t kLanes = 32 / sizeof(Real);
    enum Column {
        Origin = 0,  ///< + k: the element's origin, index axes
        Axis = 3,    ///< + 3 k + a: component a of the frame's axis k
        Half = 12,   ///< + k: half the scale along axis k, 0 where the type does not extend
        Reach = 15,  ///< + k: half the extent along axis k of a unit axis-aligned cube
        Box = 18,    ///< 1 for boxes
        Live = 19,   ///< 1 for the pairs, 0 for the padding
        Affine = 20, ///< + 12 side + 3 column + a: the affine maps (column 3: offset)
        Count = 44
    };
    struct Group {
        Real v[Count][kLanes];
    };
    size_t padded = 0;
    std::vector<Group> groups;
    Real get(int c, size_t i) const { return groups[i / kLanes].v[c][i % kLanes]; }

    PairColumns(const InverseWarp& warp, const std::vector<InverseWarp::Affine> maps[2]);
};

} // namespace

struct AdaptiveWarp::Columns {
    PairColumns<double> exact; ///< for the lattice's exact sums
    PairColumns<float> bound;  ///< for the bound (analyze())
    std::vector<float> slope;  ///< [j * padded + i]: |M_i - M_j|, the larger side (the bound's)
};

struct AdaptiveWarp::Context {
    const Occupancy* source;
    const Occupancy* target;
    const LeafFunction* fn;
    WarpLeaf leaf;
    double maxError = 0.0;
    uint64_t evaluations = 0, near = 0, allFar = 0, leaves = 0;
    // Per pair, per leaf (scratch).
    std::unique_ptr<LeafJob> job = std::make_unique<LeafJob>();
    PairBounds bounds;
    std::vector<char> isNear;
    std::vector<size_t> nearList;          ///< the near pairs, by type, then by index
    std::vector<float> termList, hessList; ///< selectNear's copies of the bound's columns
    // What analyze() found of the last cell.
    const LatticePoint* corner[8];
    bool cornersOk = false, tiny = false, coreTouches = false;
    size_t dominant = 0;
    double wMinSum = 0.0, rhoMax = 0.0, boundAllFar = 0.0;
    double wCornerMin = 0.0; ///< the smallest W at the corners (where cornersOk, else 0)
    Vec3d rhoLo[2], rhoHi[2], rhoMid[2]; ///< the box of the corners' rho_k, source and target side
    double cornerB[2][3][8]; ///< B at the corners: [side][axis][corner] (where cornersOk)
};

namespace {

/// Frobenius norm of the difference of two affine maps' linear parts (bounds the operator norm).
double linearDistance(const InverseWarp::Affine& a, const InverseWarp::Affine& b)
{
    return std::sqrt((a.col[0] - b.col[0]).lengthSqr() + (a.col[1] - b.col[1]).lengthSqr() +
                     (a.col[2] - b.col[2]).lengthSqr());
}

// The warp's vector arithmetic uses GCC's vector extension: one AVX register, or two SSE ones in
// the baseline build, with the same IEEE operations per lane in both. 8 floats: the kernel's rows
// of 8 voxels along z and the bound's 8 pairs; 4 doubles: the exact sums' 4 pairs and a leaf's 4
// corners. Loads and stores are unaligned (std::vector's storage is only 16-byte aligned) and go
// through types that alias their element type only, not the vectors' own pointers.
typedef float v8f __attribute__((vector_size(32)));
typedef int v8i __attribute__((vector_size(32)));
typedef float v8fu __attribute__((vector_size(32), aligned(4)));
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));
typedef double v4du __attribute__((vector_size(32), aligned(8)));

/// The voxels' offsets along a row (z).
constexpr v8f kZ = {0, 1, 2, 3, 4, 5, 6, 7};

VOLMORPH_ALWAYS_INLINE inline v8f load8(const float* p)
{
    return *reinterpret_cast<const v8fu*>(p);
}
VOLMORPH_ALWAYS_INLINE inline void store8(float* p, v8f v)
{
    *reinterpret_cast<v8fu*>(p) = v;
}
VOLMORPH_ALWAYS_INLINE inline v8f splat8(float v)
{
    return v8f{v, v, v, v, v, v, v, v};
}
VOLMORPH_ALWAYS_INLINE inline v8f vabs(v8f v)
{
    return reinterpret_cast<v8f>(reinterpret_cast<v8i>(v) & 0x7fffffff);
}
VOLMORPH_ALWAYS_INLINE inline v8f vmax(v8f a, v8f b)
{
    return a > b ? a : b;
}
VOLMORPH_ALWAYS_INLINE inline v8f vmin(v8f a, v8f b)
{
    return a < b ? a : b;
}
VOLMORPH_ALWAYS_INLINE inline v8f vsqrt(v8f v)
{
    v8f r;
    for (int l = 0; l < 8; ++l) r[l] = __builtin_sqrtf(v[l]); // one sqrtps per register (no errno)
    return r;
}

VOLMORPH_ALWAYS_INLINE inline v4d load4(const double* p)
{
    return *reinterpret_cast<const v4du*>(p);
}
VOLMORPH_ALWAYS_INLINE inline void store4(double* p, v4d v)
{
    *reinterpret_cast<v4du*>(p) = v;
}
VOLMORPH_ALWAYS_INLINE inline v4d splat(double v)
{
    return v4d{v, v, v, v};
}
VOLMORPH_ALWAYS_INLINE inline v4d vabs(v4d v)
{
    return reinterpret_cast<v4d>(reinterpret_cast<v4l>(v) & 0x7fffffffffffffffLL);
}
VOLMORPH_ALWAYS_INLINE inline v4d vmax(v4d a, v4d b)
{
    return a > b ? a : b;
}
VOLMORPH_ALWAYS_INLINE inline v4d vmin(v4d a, v4d b)
{
    return a < b ? a : b;
}
VOLMORPH_ALWAYS_INLINE inline v4d vsqrt(v4d v)
{
    v4d r;
    for (int l = 0; l < 4; ++l) r[l] = __builtin_sqrt(v[l]);
    return r;
}

/// Sums over pairs, 8 lanes of single precision accumulated in double (two 4-lane halves).
VOLMORPH_ALWAYS_INLINE inline v4d lowHalf(v8f v)
{
    return __builtin_convertvector(__builtin_shufflevector(v, v, 0, 1, 2, 3), v4d);
}
VOLMORPH_ALWAYS_INLINE inline v4d highHalf(v8f v)
{
    return __builtin_convertvector(__builtin_shufflevector(v, v, 4, 5, 6, 7), v4d);
}
struct WideSum {
    v4d lo{}, hi{};
    VOLMORPH_ALWAYS_INLINE void add(v8f v)
    {
        lo += lowHalf(v);
        hi += highHalf(v);
    }
    VOLMORPH_ALWAYS_INLINE double total() const
    {
        const v4d s = lo + hi;
        return (s[0] + s[1]) + (s[2] + s[3]);
    }
};

/// max(|q| - half, 0): how far a point lies beyond an element's half-extent along one of its axes.
template <class V>
VOLMORPH_ALWAYS_INLINE inline V outside(V q, V half)
{
    return vmax(vabs(q) - half, V{});
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

/// An affine function of the voxel (i, j, k), a + b i + c j + d k, as the rows walk it: a + b i at
/// each slice i in double (then single precision), c and d in single precision.
struct RowAffine {
    float start[8]; ///< at the first voxel of each slice (j = k = 0)
    float dy;       ///< step along y: from one row to the next
    float dz;       ///< step along z: from one voxel of a row to the next
    void set(double a, double b, double c, double d)
    {
        for (int i = 0; i < 8; ++i) start[i] = float(a + b * i);
        dy = float(c);
        dz = float(d);
    }
    /// At the first row of slice i; each next row of the slice adds dy.
    VOLMORPH_ALWAYS_INLINE v8f first(int i) const { return start[i] + kZ * dz; }
};

/// One near pair's share of a leaf: its element, weight scale and residuals R = A - B at the
/// leaf's origin, whose steps along the axes are the columns of M_A - M_B.
struct NearTerm {
    const Feature* element;
    double scale;
    double half[3]; ///< half the scales, 0 on the axes the type does not extend along
    Vec3d rs, drs[3], rt, drt[3];
};

/// A near pair ready for the rows: its frame coordinates and residuals over the leaf.
struct NearRows {
    RowAffine f[9]; ///< frame coordinates q, source residual, target residual
    float half[3];
    float scale;
};

/// Everything that fills one leaf's points.
struct LeafJob {
    Vec3d origin;
    /// At the leaf's corners (bit 0: +x, bit 1: +y, bit 2: +z), channels as the kernel's sums:
    /// the exact W, S - W B and T - W B, less the near pairs in fillLeafBody: the far sums.
    double far[7][8];
    std::vector<NearTerm> near; ///< grouped by type: Point, Segment, Rectangle, Box
    size_t typeEnd[4];          ///< where each type's near pairs end in `near`
    std::vector<NearRows> rows; ///< scratch, one per near pair
    InverseWarp::Affine bS, bT; ///< the dominant pair's affine maps
    double offset, exponent;
    bool inverseSquare;
};

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
                for (int c = 0; c < 3; ++c) q[c] = n.f[c].first(i);
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
            for (int c = 0; c < 6; ++c) r[c] = n.f[3 + c].first(i);
            for (int j = 0; j < 8; ++j) {
                v8f* acc = sums[8 * i + j];
                acc[0] += w[j];
                for (int c = 0; c < 6; ++c) acc[1 + c] += w[j] * r[c];
                for (int c = 0; c < 6; ++c) r[c] += n.f[3 + c].dy;
            }
        }
    }
}

/// Fills a leaf by rows of 8 voxels along z: the far sums interpolated trilinearly (slice by
/// slice, row by row), the near pairs added pair by pair over all rows, then
/// p = B(x) + residual sum / weight sum, all in single precision as the points are stored (its
/// rounding, some 1e-5 voxel at hundreds of voxels from the origin, is far below a tolerance).
template <bool InverseSquare>
VOLMORPH_ALWAYS_INLINE inline void fillLeafBody(LeafJob& job, WarpLeaf& leaf)
{
    // Per near pair: its weight w and w R (R = A - B) at the corners, taken off the exact sums
    // there, in double, 4 corners at a time (z = 0, then z = 8): what remains are the far sums.
    // Then its frame coordinates and residuals at each row's first voxel, and their steps.
    const v4d cx = {0, 8, 0, 8}, cy = {0, 0, 8, 8};
    job.rows.resize(job.near.size());
    for (size_t p = 0; p < job.near.size(); ++p) {
        const NearTerm& t = job.near[p];
        const Feature& e = *t.element;
        const Vec3d q0 = e.frameCoordinates(job.origin);
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
    // The far sums at every voxel, channels as acc below, interpolated in single precision: along
    // x on the leaf's four edges (lanes i) here, then per slice i its first and last rows (y = 0
    // and y = 8) along z, and the rows between one step along y apart (farRows).
    const v8f fraction = kZ * 0.125f; // i / 8 or k / 8
    alignas(32) float edge[7][4][8];  // per channel, (y, z) = (0, 0), (8, 0), (0, 8), (8, 8)
    for (int c = 0; c < 7; ++c) {
        const double* v = job.far[c];
        for (int m = 0; m < 4; ++m) {
            const float a = float(v[2 * m]), b = float(v[2 * m + 1]);
            store8(edge[c][m], a + fraction * (b - a));
        }
    }
    // p = B + residual sum / weight sum, B walked like the near pairs' functions.
    RowAffine b[6];
    const Vec3d bs0 = job.bS.apply(job.origin), bt0 = job.bT.apply(job.origin);
    for (int c = 0; c < 3; ++c) {
        b[c].set(bs0[c], job.bS.col[0][c], job.bS.col[1][c], job.bS.col[2][c]);
        b[3 + c].set(bt0[c], job.bT.col[0][c], job.bT.col[1][c], job.bT.col[2][c]);
    }
    if (job.near.empty()) {
        // Every pair far: the rows' sums go straight into the points (storeRow, as below, without
        // storing the sums first).
        for (int i = 0; i < 8; ++i) {
            v8f row[7], dy[7], base[6], inv[8];
            for (int c = 0; c < 7; ++c) farRows(edge[c], i, row[c], dy[c]);
            for (int c = 0; c < 6; ++c) base[c] = b[c].first(i);
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
        return;
    }
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
        for (int c = 0; c < 6; ++c) base[c] = b[c].first(i);
        for (int j = 0; j < 8; ++j) inv[j] = 1.0f / sums[8 * i + j][0];
        for (int j = 0; j < 8; ++j) {
            storeRow(leaf, 8 * i + j, base, sums[8 * i + j], inv[j]);
            for (int c = 0; c < 6; ++c) base[c] += b[c].dy;
        }
    }
}

} // namespace

AdaptiveWarp::~AdaptiveWarp() = default;

AdaptiveWarp::AdaptiveWarp(const InverseWarp& warp, double toleranceVoxels)
    : mWarp(warp), mTolerance(toleranceVoxels)
{
    const size_t n = warp.pairCount();
    for (size_t i = 0; i < n; ++i) {
        mSource.push_back(warp.sourceAffine(i));
        mTarget.push_back(warp.targetAffine(i));
    }
    const std::vector<InverseWarp::Affine> maps[2] = {mSource, mTarget};
    auto columns = std::make_unique<Columns>(
        Columns{PairColumns<double>(warp, maps), PairColumns<float>(warp, maps), {}});
    const size_t padded = columns->bound.padded;
    columns->slope.assign(n * padded, 0.0f);
    for (size_t j = 0; j < n; ++j)
        for (size_t i = 0; i < n; ++i)
            columns->slope[j * padded + i] = float(std::max(
                linearDistance(mSource[i], mSource[j]), linearDistance(mTarget[i], mTarget[j])));
    mColumns = std::move(columns);
    // The kernel's order of near pairs: by type, then by index.
    for (size_t i = 0; i < n; ++i) mByType.push_back(i);
    std::stable_sort(mByType.begin(), mByType.end(), [&warp](size_t a, size_t b) {
        return warp.interpolated(a).type < warp.interpolated(b).type;
    });
}

namespace {

template <class Real>
PairColumns<Real>::PairColumns(const InverseWarp& warp,
                               const std::vector<InverseWarp::Affine> maps[2])
{
    const size_t n = warp.pairCount();
    padded = (n + 7) / 8 * 8;
    groups.resize(padded / kLanes);
    InverseWarp::Affine zero;
    zero.col[0] = zero.col[1] = zero.col[2] = zero.offset = Vec3d(0.0);
    for (size_t i = 0; i < padded; ++i) {
        // Padding: a point at the origin with zero maps.
        const Feature e = i < n ? warp.interpolated(i) : Feature();
        const int extent = e.type == FeatureType::Point       ? 0
                           : e.type == FeatureType::Segment   ? 1
                           : e.type == FeatureType::Rectangle ? 2
                                                              : 3;
        const Vec3d* axes[3] = {&e.x, &e.y, &e.z};
        auto set = [&](int c, double v) { groups[i / kLanes].v[c][i % kLanes] = Real(v); };
        for (int k = 0; k < 3; ++k) {
            set(Origin + k, e.origin[k]);
            for (int a = 0; a < 3; ++a) set(Axis + 3 * k + a, (*axes[k])[a]);
            set(Half + k, k < extent ? 0.5 * e.scale[k] : 0.0);
            const Vec3d& ax = *axes[k];
            set(Reach + k, 0.5 * (std::abs(ax.x()) + std::abs(ax.y()) + std::abs(ax.z())));
        }
        set(Box, e.type == FeatureType::Box ? 1 : 0);
        set(Live, i < n ? 1 : 0);
        for (int side = 0; side < 2; ++side) {
            const InverseWarp::Affine& m = i < n ? maps[side][i] : zero;
            for (int a = 0; a < 3; ++a) {
                for (int k = 0; k < 3; ++k) set(Affine + 12 * side + 3 * k + a, m.col[k][a]);
                set(Affine + 12 * side + 9 + a, m.offset[a]);
            }
        }
    }
}

} // namespace

void AdaptiveWarp::identityLeaf(Context& ctx) const
{
    const Coord& o = ctx.leaf.origin;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                const Vec3f p(float(o.x() + i), float(o.y() + j), float(o.z() + k));
                ctx.leaf.set((i * 8 + j) * 8 + k, p, p);
            }
}

void AdaptiveWarp::exactLeaf(Context& ctx) const
{
    const Coord& o = ctx.leaf.origin;
    Vec3d s, t;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                mWarp.map(Vec3d(o.x() + i, o.y() + j, o.z() + k), s, t);
                ctx.leaf.set((i * 8 + j) * 8 + k, Vec3f(s), Vec3f(t));
            }
    ctx.evaluations += 512;
}

namespace {

CoordBBox widened(const Vec3d& lo, const Vec3d& hi, double margin)
{
    auto clampInt = [](double v) { return int(std::clamp(v, -1.0e9, 1.0e9)); };
    return CoordBBox(
        Coord(clampInt(std::floor(lo.x() - margin)), clampInt(std::floor(lo.y() - margin)),
              clampInt(std::floor(lo.z() - margin))),
        Coord(clampInt(std::ceil(hi.x() + margin)), clampInt(std::ceil(hi.y() + margin)),
              clampInt(std::ceil(hi.z() + margin))));
}

/// Bounding box of an affine map's image of the cube [o, o + size]^3.
void affineImage(const InverseWarp::Affine& a, const Vec3d& o, double size, Vec3d& lo, Vec3d& hi)
{
    lo = hi = a.apply(o);
    for (int c = 0; c < 3; ++c) {
        const Vec3d step = a.col[c] * size;
        for (int k = 0; k < 3; ++k) (step[k] < 0 ? lo : hi)[k] += step[k];
    }
}

/// Trilinear sampling reads up to one voxel past the point.
constexpr double kSamplerReach = 1.5;

bool touches(const Occupancy* occ, const Vec3d& lo, const Vec3d& hi, double margin)
{
    return occ && occ->anyIn(widened(lo, hi, margin));
}

// The leaf kernel is compiled three times on x86-64 with GCC: for AVX2 (8 voxels of a row in one
// instruction), for AVX2 with AVX-512VL (the same 8-lane code with 32 vector registers instead
// of 16: fewer spills, about 2% less time) and for the baseline, and picked by the CPU at run time.
// Each lane does the same IEEE operations in every build (no FMA contraction: -ffp-contract=off
// on this file), so the points are bit-identical whatever the machine; the warp tests check it
// with useKernelBuild.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define VOLMORPH_HAVE_AVX2_KERNEL 1
#define VOLMORPH_AVX2 __attribute__((target("avx2")))
#define VOLMORPH_AVX512 __attribute__((target("avx2,avx512f,avx512vl,avx512dq,avx512bw")))
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

/// The most capable build allowed (useKernelBuild).
std::atomic<int> gKernelLimit{int(KernelBuild::Avx512)};

/// The build of the kernels that runs: the most capable one the CPU has, within the limit.
KernelBuild kernelBuild()
{
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
    static const KernelBuild best =
        __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw")
            ? KernelBuild::Avx512
        : __builtin_cpu_supports("avx2") ? KernelBuild::Avx2
                                         : KernelBuild::Baseline;
    return KernelBuild(std::min(int(best), gKernelLimit.load(std::memory_order_relaxed)));
#else
    return KernelBuild::Baseline;
#endif
}

void fillLeaf(LeafJob& job, WarpLeaf& leaf)
{
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
    switch (kernelBuild()) {
    case KernelBuild::Avx512:
        return fillLeafAvx512(job, leaf);
    case KernelBuild::Avx2:
        return fillLeafAvx2(job, leaf);
    case KernelBuild::Baseline:
        break;
    }
#endif
    fillLeafBaseline(job, leaf);
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

void leafRange(const WarpLeaf& leaf, Vec3f lo[2], Vec3f hi[2])
{
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
    switch (kernelBuild()) {
    case KernelBuild::Avx512:
        return leafRangeAvx512(leaf, lo, hi);
    case KernelBuild::Avx2:
        return leafRangeAvx2(leaf, lo, hi);
    case KernelBuild::Baseline:
        break;
    }
#endif
    leafRangeBody(leaf, lo, hi);
}

} // namespace

void useKernelBuild(KernelBuild limit)
{
    gKernelLimit = int(limit);
}

KernelBuild activeKernelBuild()
{
    return kernelBuild();
}

/// The bound's terms of every pair over the cube [o, o + size]^3 (a leaf: its voxels and its far
/// corners), into ctx; see the header for the derivation. The per-pair loops take 8 pairs at a
/// time in single precision; the sums over pairs are in double.
VOLMORPH_ALWAYS_INLINE inline void AdaptiveWarp::analyzeBody(Context& ctx,
                                                             const LatticePoint* const corners[8],
                                                             const Coord& origin, int size) const
{
    const size_t n = mWarp.pairCount();
    const PairColumns<float>& col = mColumns->bound;
    const size_t padded = col.padded;
    ctx.cornersOk = true;
    ctx.wCornerMin = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 8; ++k) {
        ctx.corner[k] = corners[k];
        ctx.cornersOk = ctx.cornersOk && corners[k]->ok;
        if (ctx.cornersOk) ctx.wCornerMin = std::min(ctx.wCornerMin, corners[k]->w);
    }
    // Less a margin for the rounding of W to single precision in the kernel.
    ctx.wCornerMin = ctx.cornersOk ? ctx.wCornerMin * (1.0 - 1e-6) : 0.0;
    const Vec3d o = origin.asVec3d();
    const double h = size, halfDiagonal = 0.5 * h * std::sqrt(3.0);
    const Vec3d centre = o + Vec3d(0.5 * h);
    const Vec3f cf(centre);
    const float hf = float(h), halfDiagonalF = float(halfDiagonal);
    const float offset = float(mWarp.weightOffset()), b = float(mWarp.weightExponent());
    const bool inverseSquare = mWarp.weighting() == Weighting::InverseSquare;
    PairBounds& pb = ctx.bounds;
    pb.resize(padded);
    using C = PairBounds::Column;
    using PC = PairColumns<float>;
    const v8f zero = splat8(0.0f), one = splat8(1.0f),
              infinity = splat8(std::numeric_limits<float>::infinity());

    // Per pair: frame coordinates q of the centre, the distance dc = |max(|q| - half, 0)| (half 0
    // on the axes a type does not extend along), its gradient g in index axes, the smallest
    // distance over the cube, and whether a box contains the whole cube (d = 0, w constant).
    // Over the pairs: the smallest total weight, whether any weight is too steep (below
    // kTinyRadius or beyond single precision: the leaf is then evaluated exactly), and the
    // dominant pair (the largest weight at the centre; the first such pair), per lane.
    WideSum wMinTotal;
    v8i steep{}, bestIndex{};
    v8f best = splat8(-1.0f);
    const v8i laneIndex = {0, 1, 2, 3, 4, 5, 6, 7};
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        const v8i live = load8(cg.v[PC::Live]) != zero;
        const v8f p[3] = {cf.x() - load8(cg.v[PC::Origin + 0]),
                          cf.y() - load8(cg.v[PC::Origin + 1]),
                          cf.z() - load8(cg.v[PC::Origin + 2])};
        v8f q[3], v[3], out2 = zero;
        v8i inside = load8(cg.v[PC::Box]) != zero;
        for (int k = 0; k < 3; ++k) {
            q[k] = load8(cg.v[PC::Axis + 3 * k + 0]) * p[0] +
                   load8(cg.v[PC::Axis + 3 * k + 1]) * p[1] +
                   load8(cg.v[PC::Axis + 3 * k + 2]) * p[2];
            const v8f d = outside(q[k], load8(cg.v[PC::Half + k]));
            out2 += d * d;
            v[k] = q[k] < zero ? -d : d;
            inside &= vabs(q[k]) + hf * load8(cg.v[PC::Reach + k]) <= load8(cg.v[PC::Half + k]);
        }
        const v8f d = vsqrt(out2);
        const v8i positive = d > zero;
        const v8f inv = positive ? one / d : zero;
        v8f gL1 = zero, g[3];
        for (int a = 0; a < 3; ++a) {
            g[a] = (load8(cg.v[PC::Axis + 3 * 0 + a]) * v[0] +
                    load8(cg.v[PC::Axis + 3 * 1 + a]) * v[1] +
                    load8(cg.v[PC::Axis + 3 * 2 + a]) * v[2]) *
                   inv;
            gL1 += vabs(g[a]);
        }
        // d is convex (the distance to a convex set), so it lies above its tangent plane at the
        // centre: over the cube, d >= dc - h/2 |g|_1.
        const v8f dMin = positive ? vmax(zero, d - (0.5f * hf) * gL1) : zero;
        // And it lies below the distance to the centre's nearest point on the element, c - d g:
        // |x - c + d g|^2 = |x - c|^2 + 2 d g.(x - c) + d^2 <= 3 h^2/4 + h d |g|_1 + d^2 over the
        // cube (d + halfDiagonal only where g is along a diagonal).
        const v8f dMax =
            vmin(d + halfDiagonalF, vsqrt((d * d + (hf * d) * gL1) + (0.75f * hf * hf)));
        const v8f rMin = offset + dMin, rMax = offset + (inside ? zero : dMax);
        store8(pg.v[C::Constant], inside ? one : zero);
        // Weights at the smallest and largest distance and at the centre.
        v8f wMax, wMin, wc;
        if (inverseSquare) {
            const v8f r0 = vmax(dMin, splat8(float(kTinyRadius) - offset)) + offset,
                      r2 = d + offset;
            wMax = one / (r0 * r0);
            wMin = one / (rMax * rMax);
            wc = one / (r2 * r2);
        } else {
            for (int l = 0; l < 8; ++l) {
                const size_t j = std::min(i + l, n - 1); // padding lanes: any pair's values
                wMax[l] = float(mWarp.weightAt(j, std::max(double(dMin[l]), kTinyRadius - offset)));
                wMin[l] = float(mWarp.weightAt(j, double(rMax[l]) - offset));
                wc[l] = float(mWarp.weightAt(j, d[l]));
            }
        }
        store8(pg.v[C::WMax], wMax);
        wMinTotal.add(live ? wMin : zero);
        steep |=
            live & ((rMin < float(kTinyRadius)) | ~(wMax <= std::numeric_limits<float>::max()));
        const v8f centreWeight = live ? wc : splat8(-1.0f);
        const v8i better = centreWeight > best;
        best = better ? centreWeight : best;
        bestIndex = better ? int(i) + laneIndex : bestIndex;
        // |grad w| and |Hess w| over the cube. Per axis a: |w_a| = b w / r |d_a| and
        // w_aa = w (b (b + 1) / r^2 (d_a)^2 - b / r d_aa). Hess d is positive semidefinite (d is
        // convex), has grad d as a null vector and eigenvalues at most 1 / d, so
        // 0 <= d_aa <= (1 - (d_a)^2) / d, and the two terms of w_aa, of opposite signs, bound it by
        // the larger. grad d is the unit vector from the element's nearest point; over the cube it
        // turns by at most |Hess d| halfDiagonal <= halfDiagonal / dMin, so
        // |g_a| - turn <= |d_a| <= |g_a| + turn. w1 bounds sqrt(sum_a sup (w_a)^2), w2 bounds
        // sum_a sup |w_aa|; where the cube touches the element (dMin = 0) there is a kink: w2 is
        // infinite.
        const v8i apart = dMin > zero;
        const v8f invD = one / (apart ? dMin : one), invR = one / rMin;
        const v8f turn = vmin(one, halfDiagonalF * invD);
        const v8f bend = (b * (b + 1.0f)) * invR, curve = b * invD;
        // Along axis a, the slice s voxels from the cube's face nearest the element is s |g_a|
        // farther (d lies above its tangent plane at the centre), so with w ~ r^-b both sups over
        // it are at most (1 + kappa s)^-(b + 1) times those over the cube, kappa = |g_a| / rMin
        // (d / dMin grows at least as fast as r / rMin). Linear interpolation's error at x is
        // the integral of its Peano kernel G(x, s) against u''; with |u''(s)| <= M (1 + kappa s)^-3
        // its largest value over x is, in closed form, h^2/8 M (2 / (q (q + 1)))^2 with
        // q = sqrt(1 + kappa h) (1 where kappa = 0): each axis's share carries that factor (1 for
        // Beier-Neely's law, whose exponent may be below 2).
        v8f axial = zero, curved = zero;
        for (int a = 0; a < 3; ++a) {
            const v8f hi = vmin(one, vabs(g[a]) + turn), lo = vmax(zero, vabs(g[a]) - turn);
            v8f share = one;
            if (inverseSquare) {
                const v8f kh = (hf * vabs(g[a])) * invR,
                          f = 2.0f / ((one + kh) + vsqrt(one + kh)); // q (q + 1) = q^2 + q
                share = f * f;
            }
            axial += (share * hi) * (share * hi);
            curved += share * vmax(bend * (hi * hi), curve * (one - lo * lo));
        }
        const v8f slopeBound = b * wMax * invR;
        const v8f first = apart ? slopeBound * vsqrt(axial) : slopeBound;
        const v8f second = apart ? wMax * invR * curved : infinity;
        store8(pg.v[C::W1], inside ? zero : first);
        store8(pg.v[C::W2], inside ? zero : second);
    }
    const double wMinSum = ctx.wMinSum = wMinTotal.total();
    ctx.tiny = false;
    size_t dominant = 0;
    float wCentreMax = -1.0f;
    for (int l = 0; l < 8; ++l) {
        ctx.tiny = ctx.tiny || steep[l];
        if (best[l] > wCentreMax || (best[l] == wCentreMax && size_t(bestIndex[l]) < dominant)) {
            wCentreMax = best[l];
            dominant = size_t(bestIndex[l]);
        }
    }
    ctx.dominant = dominant;
    const InverseWarp::Affine& bS = mSource[dominant];
    const InverseWarp::Affine& bT = mTarget[dominant];
    const float* slope = &mColumns->slope[dominant * padded];

    // R_i = A_i - B at the centre, |R_i| over the cube on either side (|M_i - M_B| the slope),
    // and |rho| = |p - B| <= sum w_i |R_i| / W.
    const Vec3f bc[2] = {Vec3f(bS.apply(centre)), Vec3f(bT.apply(centre))};
    WideSum rhoTotal;
    v8f residLargest = zero;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        const v8i live = load8(cg.v[PC::Live]) != zero;
        v8f length2[2];
        for (int side = 0; side < 2; ++side) {
            length2[side] = zero;
            for (int a = 0; a < 3; ++a) {
                const v8f r = load8(cg.v[PC::Affine + 12 * side + 3 * 0 + a]) * cf.x() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 1 + a]) * cf.y() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 2 + a]) * cf.z() +
                              load8(cg.v[PC::Affine + 12 * side + 3 * 3 + a]) - bc[side][a];
                store8(pg.v[(side == 0 ? C::RS0 : C::RT0) + a], r);
                length2[side] += r * r;
            }
        }
        const v8f resid = vsqrt(vmax(length2[0], length2[1])) + load8(&slope[i]) * halfDiagonalF;
        store8(pg.v[C::Resid], resid);
        const v8f wMax = live ? load8(pg.v[C::WMax]) : zero, residLive = live ? resid : zero;
        rhoTotal.lo += lowHalf(wMax) * lowHalf(residLive); // products of floats, exact in double
        rhoTotal.hi += highHalf(wMax) * highHalf(residLive);
        residLargest = vmax(residLargest, residLive);
    }
    const double rhoSum = rhoTotal.total();
    double residMax = 0.0;
    for (int l = 0; l < 8; ++l) residMax = std::max(residMax, double(residLargest[l]));
    const double rhoMax = ctx.rhoMax = std::min(residMax, rhoSum / wMinSum);

    // Each far pair's share of the bound; one pair is its own affine map (R = 0, rho = 0).
    const float k = float(kBoundScale * h * h / 8.0), rhoMaxF = float(rhoMax);
    const v8f none = n == 1 ? one : zero;
    WideSum termTotal, hessTotal;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        const v8f w1 = load8(pg.v[C::W1]), w2 = load8(pg.v[C::W2]);
        const v8i skip =
            (load8(pg.v[C::Constant]) != zero) | (none != zero) | (load8(cg.v[PC::Live]) == zero);
        const v8f term =
            skip ? zero
            : w2 == infinity
                ? infinity
                : k * ((load8(pg.v[C::Resid]) + rhoMaxF) * w2 + 2.0f * load8(&slope[i]) * w1);
        const v8f hess = skip ? zero : k * w2;
        store8(pg.v[C::Hess], hess);
        store8(pg.v[C::Term], term);
        termTotal.add(term);
        hessTotal.add(hess);
    }
    const double hess = hessTotal.total();
    // With every pair far, the interpolated W is a convex combination of the corners' W.
    ctx.boundAllFar = bound(ctx, termTotal.total(), hess, ctx.wCornerMin);

    // A second, tighter pass where that bound is finite. A far pair's share of the error is
    // (R_i(c) - rho(x)) (I[w_i] - w_i) + D_i (I[w_i (x - c)] - w_i (x - c)), c the centre and
    // D_i = M_i - M_B, so |R_i(c)| + |rho| above may be replaced by |R_i(c) - rho(x)|. The
    // all-far interpolant's rho lies in the hull of the corners' rho_k and within boundAllFar of
    // the true rho: |R_i(c) - rho(x)| <= |R_i(c) - rho_0| + r + boundAllFar, with rho_0 the
    // centre of the corners' box and r its largest distance to a corner (each side).
    // The corners' residuals rho_k = p_k - B(x_k): their box on each side (the domain test uses
    // it too), its centre rho_0 and largest distance r.
    if (!ctx.cornersOk) return;
    // Corners 0-3 (z = 0) and 4-7 (z = h), 4 lanes each; B(x) as Affine::apply computes it.
    const v4d cornerX = o.x() + v4d{0, h, 0, h}, cornerY = o.y() + v4d{0, 0, h, h};
    const v4d cornerZ[2] = {splat(o.z()), splat(o.z() + h)};
    v4d inverseW[2]; // 1 / w at the corners
    for (int m = 0; m < 2; ++m) {
        for (int l = 0; l < 4; ++l) inverseW[m][l] = corners[4 * m + l]->w;
        inverseW[m] = 1.0 / inverseW[m];
    }
    double radius[2];
    for (int side = 0; side < 2; ++side) {
        const InverseWarp::Affine& bA = side == 0 ? bS : bT;
        v4d rho[3][2];
        for (int a = 0; a < 3; ++a)
            for (int m = 0; m < 2; ++m) {
                const v4d bx = ((bA.col[0][a] * cornerX + bA.col[1][a] * cornerY) +
                                bA.col[2][a] * cornerZ[m]) +
                               bA.offset[a];
                store4(&ctx.cornerB[side][a][4 * m], bx);
                v4d sum; // S or T
                for (int l = 0; l < 4; ++l) {
                    const LatticePoint& q = *corners[4 * m + l];
                    sum[l] = (side == 0 ? q.s : q.t)[a];
                }
                rho[a][m] = sum * inverseW[m] - bx; // the exact point S / W less B
            }
        Vec3d lo, hi;
        for (int a = 0; a < 3; ++a) {
            const v4d l = vmin(rho[a][0], rho[a][1]), u = vmax(rho[a][0], rho[a][1]);
            lo[a] = std::min(std::min(l[0], l[1]), std::min(l[2], l[3]));
            hi[a] = std::max(std::max(u[0], u[1]), std::max(u[2], u[3]));
        }
        ctx.rhoLo[side] = lo;
        ctx.rhoHi[side] = hi;
        const Vec3d mid = ctx.rhoMid[side] = 0.5 * (lo + hi);
        v4d r2 = splat(0.0);
        for (int m = 0; m < 2; ++m) {
            const v4d dx = rho[0][m] - mid.x(), dy = rho[1][m] - mid.y(), dz = rho[2][m] - mid.z();
            r2 = vmax(r2, (dx * dx + dy * dy) + dz * dz);
        }
        radius[side] = std::sqrt(std::max(std::max(r2[0], r2[1]), std::max(r2[2], r2[3])));
    }
    if (!std::isfinite(ctx.boundAllFar) || n == 1) return;
    const Vec3f mid[2] = {Vec3f(ctx.rhoMid[0]), Vec3f(ctx.rhoMid[1])};
    const float boundAllFar = float(ctx.boundAllFar), radiusS = float(radius[0]),
                radiusT = float(radius[1]);
    WideSum tightTotal;
    for (size_t i = 0; i < padded; i += 8) {
        const PC::Group& cg = col.groups[i / 8];
        PairBounds::Group& pg = pb.groups[i / 8];
        v8f length2[2] = {zero, zero};
        for (int a = 0; a < 3; ++a) {
            const v8f ds = load8(pg.v[C::RS0 + a]) - mid[0][a],
                      dt = load8(pg.v[C::RT0 + a]) - mid[1][a];
            length2[0] += ds * ds;
            length2[1] += dt * dt;
        }
        const v8f w1 = load8(pg.v[C::W1]), w2 = load8(pg.v[C::W2]), term = load8(pg.v[C::Term]);
        const v8f apart = vmax(vsqrt(length2[0]) + radiusS, vsqrt(length2[1]) + radiusT) +
                          load8(&slope[i]) * halfDiagonalF + boundAllFar;
        const v8i tighter = (term != infinity) & (load8(pg.v[C::Constant]) == zero) &
                            (apart < load8(pg.v[C::Resid]) + rhoMaxF);
        const v8f tightTerm = tighter ? k * (apart * w2 + 2.0f * load8(&slope[i]) * w1) : term;
        store8(pg.v[C::Term], tightTerm);
        tightTotal.add(load8(cg.v[PC::Live]) != zero ? tightTerm
                                                     : zero); // padding lanes hold no pair
    }
    ctx.boundAllFar =
        std::min(ctx.boundAllFar, bound(ctx, tightTotal.total(), hess, ctx.wCornerMin));
}

/// The exact warp's unnormalized sums W = sum w_i, S = sum w_i A_S,i, T = sum w_i A_T,i at x (so
/// that S / W and T / W are InverseWarp::map's points), over the pairs' columns, 4 at a time.
VOLMORPH_ALWAYS_INLINE inline bool AdaptiveWarp::exactSumsBody(const Vec3d& x,
                                                               LatticePoint& out) const
{
    const size_t n = mWarp.pairCount();
    const PairColumns<double>& col = mColumns->exact;
    const double offset = mWarp.weightOffset();
    const bool inverseSquare = mWarp.weighting() == Weighting::InverseSquare;
    const v4d zero = splat(0.0), one = splat(1.0);
    v4d W = zero, S[3] = {zero, zero, zero}, T[3] = {zero, zero, zero};
    v4l onElement = v4l{0, 0, 0, 0};
    using PC = PairColumns<double>;
    for (size_t i = 0; i < col.padded; i += 4) {
        const PC::Group& cg = col.groups[i / 4];
        const v4d p[3] = {x.x() - load4(cg.v[PC::Origin + 0]), x.y() - load4(cg.v[PC::Origin + 1]),
                          x.z() - load4(cg.v[PC::Origin + 2])};
        v4d out2 = zero;
        for (int k = 0; k < 3; ++k) {
            const v4d q = load4(cg.v[PC::Axis + 3 * k + 0]) * p[0] +
                          load4(cg.v[PC::Axis + 3 * k + 1]) * p[1] +
                          load4(cg.v[PC::Axis + 3 * k + 2]) * p[2];
            const v4d d = outside(q, load4(cg.v[PC::Half + k]));
            out2 += d * d;
        }
        const v4d d = vsqrt(out2), r = d + offset;
        const v4l live = load4(cg.v[PC::Live]) != zero;
        onElement |= live & (r < InverseWarp::kOnElement);
        v4d w;
        if (inverseSquare) {
            w = one / (r * r);
        } else {
            for (int l = 0; l < 4; ++l) w[l] = mWarp.weightAt(std::min(i + l, n - 1), d[l]);
        }
        w = live ? w : zero;
        W += w;
        for (int a = 0; a < 3; ++a) {
            S[a] += w * (load4(cg.v[PC::Affine + 3 * 0 + a]) * x.x() +
                         load4(cg.v[PC::Affine + 3 * 1 + a]) * x.y() +
                         load4(cg.v[PC::Affine + 3 * 2 + a]) * x.z() +
                         load4(cg.v[PC::Affine + 3 * 3 + a]));
            T[a] += w * (load4(cg.v[PC::Affine + 12 + 3 * 0 + a]) * x.x() +
                         load4(cg.v[PC::Affine + 12 + 3 * 1 + a]) * x.y() +
                         load4(cg.v[PC::Affine + 12 + 3 * 2 + a]) * x.z() +
                         load4(cg.v[PC::Affine + 12 + 3 * 3 + a]));
        }
    }
    auto total = [](v4d v) { return (v[0] + v[1]) + (v[2] + v[3]); };
    out.w = total(W);
    out.s = Vec3d(total(S[0]), total(S[1]), total(S[2]));
    out.t = Vec3d(total(T[0]), total(T[1]), total(T[2]));
    const bool on = onElement[0] || onElement[1] || onElement[2] || onElement[3];
    return !on && std::isfinite(out.w) && out.w > 0.0;
}

#ifdef VOLMORPH_HAVE_AVX2_KERNEL
VOLMORPH_AVX2 void AdaptiveWarp::analyzeAvx2(Context& ctx, const LatticePoint* const corners[8],
                                             const Coord& origin, int size) const
{
    analyzeBody(ctx, corners, origin, size);
}
VOLMORPH_AVX512 void AdaptiveWarp::analyzeAvx512(Context& ctx, const LatticePoint* const corners[8],
                                                 const Coord& origin, int size) const
{
    analyzeBody(ctx, corners, origin, size);
}
VOLMORPH_AVX2 bool AdaptiveWarp::exactSumsAvx2(const Vec3d& x, LatticePoint& out) const
{
    return exactSumsBody(x, out);
}
VOLMORPH_AVX512 bool AdaptiveWarp::exactSumsAvx512(const Vec3d& x, LatticePoint& out) const
{
    return exactSumsBody(x, out);
}
#endif

bool AdaptiveWarp::exactSums(const Vec3d& x, LatticePoint& out) const
{
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
    switch (kernelBuild()) {
    case KernelBuild::Avx512:
        return exactSumsAvx512(x, out);
    case KernelBuild::Avx2:
        return exactSumsAvx2(x, out);
    case KernelBuild::Baseline:
        break;
    }
#endif
    return exactSumsBody(x, out);
}

void AdaptiveWarp::analyze(Context& ctx, const LatticePoint* const corners[8], const Coord& origin,
                           int size) const
{
#ifdef VOLMORPH_HAVE_AVX2_KERNEL
    switch (kernelBuild()) {
    case KernelBuild::Avx512:
        return analyzeAvx512(ctx, corners, origin, size);
    case KernelBuild::Avx2:
        return analyzeAvx2(ctx, corners, origin, size);
    case KernelBuild::Baseline:
        break;
    }
#endif
    analyzeBody(ctx, corners, origin, size);
}

// The domain, before any voxel. With every pair far the interpolant is B + I[G] / I[W], and
// I[G] / I[W] is a convex combination of the corners' rho_k = G_k / W_k: the image lies within
// B(cube) + hull(rho_k), widened by the bound. Otherwise p = B + rho with |rho| <= rhoMax.
bool AdaptiveWarp::mayTouch(Context& ctx, const Coord& origin, int size) const
{
    const double h = size, rhoMax = ctx.rhoMax, boundAllFar = ctx.boundAllFar;
    const Vec3d o = origin.asVec3d();
    const InverseWarp::Affine& bS = mSource[ctx.dominant];
    const InverseWarp::Affine& bT = mTarget[ctx.dominant];
    // The corners' residuals rho_k = p_k - B(x_k), each side (their box from analyze()).
    Vec3d rsLo(-rhoMax), rsHi(rhoMax), rtLo(-rhoMax), rtHi(rhoMax);
    if (ctx.cornersOk) {
        rsLo = ctx.rhoLo[0];
        rsHi = ctx.rhoHi[0];
        rtLo = ctx.rhoLo[1];
        rtHi = ctx.rhoHi[1];
    }
    Vec3d sLo, sHi, tLo, tHi;
    affineImage(bS, o, h, sLo, sHi);
    affineImage(bT, o, h, tLo, tHi);
    // Where the corners themselves land: a cube whose corners' box touches an occupied block is
    // kept without a second test on its filled points.
    ctx.coreTouches =
        ctx.cornersOk && (touches(ctx.source, sLo + rsLo, sHi + rsHi, kSamplerReach) ||
                          touches(ctx.target, tLo + rtLo, tHi + rtHi, kSamplerReach));
    if (ctx.coreTouches) return true;
    if (ctx.cornersOk && boundAllFar < rhoMax) {
        const double margin = kSamplerReach + boundAllFar;
        return touches(ctx.source, sLo + rsLo, sHi + rsHi, margin) ||
               touches(ctx.target, tLo + rtLo, tHi + rtHi, margin);
    }
    const double margin = kSamplerReach + rhoMax;
    return touches(ctx.source, sLo, sHi, margin) || touches(ctx.target, tLo, tHi, margin);
}

double AdaptiveWarp::bound(const Context& ctx, double terms, double hess, double floor) const
{
    // The far pairs' terms over the smallest interpolated total weight W_E + I[W_F]: at least
    // the smallest total weight less what interpolating W_F may take, and at least `floor`
    // (with every pair far, I[W] is a convex combination of the corners' W: their smallest).
    const double denominator = std::max(ctx.wMinSum - hess, floor);
    return std::isfinite(terms) && denominator > 0.0 ? terms / denominator
                                                     : std::numeric_limits<double>::infinity();
}

double AdaptiveWarp::selectNear(Context& ctx, size_t& nearCount) const
{
    // Largest share first, until the far pairs' bound is within the tolerance: the far sums are
    // the totals less the near pairs' shares (infinite shares, kinks, counted apart).
    const size_t n = mWarp.pairCount();
    // The terms and Hessian bounds, in pair order (from their groups).
    std::vector<float>& term = ctx.termList;
    std::vector<float>& hess = ctx.hessList;
    term.resize(n);
    hess.resize(n);
    for (size_t i = 0; i < n; ++i) {
        term[i] = ctx.bounds.get(PairBounds::Term, i);
        hess[i] = ctx.bounds.get(PairBounds::Hess, i);
    }
    ctx.isNear.assign(n, 0);
    double terms = 0.0, hessSum = 0.0;
    size_t kinks = 0;
    for (size_t i = 0; i < n; ++i) {
        if (std::isfinite(term[i])) {
            terms += term[i];
            hessSum += hess[i];
        } else {
            ++kinks;
        }
    }
    nearCount = 0;
    double b = ctx.boundAllFar;
    while (b > mTolerance && nearCount < n) {
        size_t best = n;
        for (size_t i = 0; i < n; ++i)
            if (!ctx.isNear[i] && (best == n || term[i] > term[best])) best = i;
        ctx.isNear[best] = 1;
        ++nearCount;
        if (std::isfinite(term[best])) {
            terms = std::max(0.0, terms - term[best]);
            hessSum = std::max(0.0, hessSum - hess[best]);
        } else {
            --kinks;
        }
        b = kinks > 0 ? std::numeric_limits<double>::infinity() : bound(ctx, terms, hessSum, 0.0);
    }
    ctx.nearList.clear();
    for (size_t k = 0; nearCount > 0 && k < n; ++k)
        if (ctx.isNear[mByType[k]]) ctx.nearList.push_back(mByType[k]);
    return nearCount == n ? 0.0 : b; // every pair near: exact at every voxel but for rounding
}

void AdaptiveWarp::fill(Context& ctx, const Coord& origin) const
{
    const Vec3d o = origin.asVec3d();
    const InverseWarp::Affine& bS = mSource[ctx.dominant];
    const InverseWarp::Affine& bT = mTarget[ctx.dominant];

    // The exact sums at the corners, as W, S - W B and T - W B (B at the corners from analyze());
    // the kernel takes the near pairs off them (G = N - W B - sum_E w_i R_i, W_F = W - sum_E w_i).
    LeafJob& job = *ctx.job;
    for (int c = 0; c < 8; ++c) {
        const LatticePoint& p = *ctx.corner[c];
        job.far[0][c] = p.w;
        for (int k = 0; k < 3; ++k) {
            job.far[1 + k][c] = p.s[k] - p.w * ctx.cornerB[0][k][c];
            job.far[4 + k][c] = p.t[k] - p.w * ctx.cornerB[1][k][c];
        }
    }
    job.origin = o;
    job.bS = bS;
    job.bT = bT;
    job.offset = mWarp.weightOffset();
    job.exponent = mWarp.weightExponent();
    job.inverseSquare = mWarp.weighting() == Weighting::InverseSquare;
    job.near.clear();
    const Vec3d bso = bS.apply(o), bto = bT.apply(o);
    for (int type = 0; type < 4; ++type) job.typeEnd[type] = 0;
    for (const size_t p : ctx.nearList) { // by type, then by index
        NearTerm t;
        t.element = &mWarp.interpolated(p);
        t.scale = mWarp.weightScale(p);
        for (int k = 0; k < 3; ++k)
            t.half[k] = mColumns->exact.get(PairColumns<double>::Half + k, p);
        t.rs = mSource[p].apply(o) - bso;
        t.rt = mTarget[p].apply(o) - bto;
        for (int k = 0; k < 3; ++k) {
            t.drs[k] = mSource[p].col[k] - bS.col[k];
            t.drt[k] = mTarget[p].col[k] - bT.col[k];
        }
        job.near.push_back(t);
        ++job.typeEnd[int(mWarp.interpolated(p).type)];
    }
    for (int type = 1; type < 4; ++type)
        job.typeEnd[type] += job.typeEnd[type - 1]; // counts to ends
    fillLeaf(job, ctx.leaf);
}

void AdaptiveWarp::leaf(Context& ctx, const Lattice& lattice, const Coord& origin) const
{
    ctx.leaf.origin = origin;
    const bool cull = ctx.source || ctx.target;
    const size_t n = mWarp.pairCount();
    const Vec3d o = origin.asVec3d();
    // `recheck`: cull again by the filled points, when only the bound's margin kept the leaf.
    auto visit = [&](double errorBound, bool recheck) {
        if (cull && recheck) {
            // The filled points' own bounding box, widened by what they may be off.
            Vec3f lo[2], hi[2];
            leafRange(ctx.leaf, lo, hi);
            const double margin = kSamplerReach + errorBound;
            if (!touches(ctx.source, Vec3d(lo[0]), Vec3d(hi[0]), margin) &&
                !touches(ctx.target, Vec3d(lo[1]), Vec3d(hi[1]), margin))
                return;
        }
        ++ctx.leaves;
        ctx.leaf.errorBound = errorBound;
        (*ctx.fn)(ctx.leaf);
    };

    if (n == 0) {
        if (cull && !touches(ctx.source, o, o + Vec3d(7.0), kSamplerReach) &&
            !touches(ctx.target, o, o + Vec3d(7.0), kSamplerReach))
            return;
        identityLeaf(ctx);
        ctx.leaf.errorBound = 0.0;
        ++ctx.leaves;
        (*ctx.fn)(ctx.leaf);
        return;
    }

    const Coord lc(origin.x() >> 3, origin.y() >> 3, origin.z() >> 3);
    const LatticePoint* corners[8];
    for (int k = 0; k < 8; ++k)
        corners[k] = &lattice.points[lattice.index(lc.offsetBy(k & 1, (k >> 1) & 1, (k >> 2) & 1))];
    analyze(ctx, corners, origin, 8);
    if (cull && !mayTouch(ctx, origin, 8)) return;
    if (mTolerance <= 0.0 || !ctx.cornersOk || ctx.tiny) {
        exactLeaf(ctx);
        visit(0.0, !ctx.coreTouches);
        return;
    }

    size_t nearCount = 0;
    const double bound = selectNear(ctx, nearCount);
    const uint64_t near = uint64_t(nearCount) * 512;
    fill(ctx, origin);
    ctx.near += near;
    ctx.allFar += nearCount == 0;
    ctx.maxError = std::max(ctx.maxError, bound);
    visit(bound, !ctx.coreTouches);
}

void AdaptiveWarp::forEachLeaf(const CoordBBox& box, const Occupancy* source,
                               const Occupancy* target, const LeafFunction& fn,
                               AdaptiveWarpStats* stats, Interrupter* interrupter,
                               const CellFilter* wanted) const
{
    if (box.empty()) return;
    const size_t n = mWarp.pairCount();
    auto down = [](int v, int size) {
        return v >= 0 ? v / size * size : -((-v + size - 1) / size) * size;
    };

    // 1. Candidate cells of 2^3 leaves (16 voxels), each with the mask of its leaves that lie in
    //    the box and are wanted, gathered per top cell: top cells the filter refuses, or whose
    //    image under every pair's affine map (the warp is a convex combination of them) misses
    //    both sides' occupied blocks, are skipped whole.
    struct Cell {
        Coord origin;
        uint8_t leaves; ///< bit (x << 2 | y << 1 | z): the leaf at origin + 8 (x, y, z)
    };
    const Coord lo(down(box.min().x(), kTopCell), down(box.min().y(), kTopCell),
                   down(box.min().z(), kTopCell));
    std::vector<Coord> tops;
    for (int x = lo.x(); x <= box.max().x(); x += kTopCell)
        for (int y = lo.y(); y <= box.max().y(); y += kTopCell)
            for (int z = lo.z(); z <= box.max().z(); z += kTopCell) tops.emplace_back(x, y, z);
    std::vector<std::vector<Cell>> perTop(tops.size());
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, tops.size(), 1), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t ti = r.begin(); ti != r.end(); ++ti) {
                const CoordBBox cube = CoordBBox::createCube(tops[ti], kTopCell);
                if (wanted && !(*wanted)(cube)) continue;
                if ((source || target) && n > 0) {
                    Vec3d slo(std::numeric_limits<double>::max()), shi(-slo), tlo(slo), thi(-slo);
                    for (size_t i = 0; i < n; ++i) {
                        Vec3d a, c;
                        affineImage(mSource[i], cube.min().asVec3d(), kTopCell, a, c);
                        slo = minComponent(slo, a);
                        shi = maxComponent(shi, c);
                        affineImage(mTarget[i], cube.min().asVec3d(), kTopCell, a, c);
                        tlo = minComponent(tlo, a);
                        thi = maxComponent(thi, c);
                    }
                    if (!touches(source, slo, shi, kSamplerReach) &&
                        !touches(target, tlo, thi, kSamplerReach))
                        continue;
                }
                CoordBBox part = cube;
                part.intersect(box);
                if (part.empty()) continue;
                const CoordBBox leafRange(Coord(down(part.min().x(), 8), down(part.min().y(), 8),
                                                down(part.min().z(), 8)),
                                          part.max()); // the leaves' origins
                // Cells in the order of their blocks of 2^3 cells (step 2 culls blocks, then
                // cells).
                const CoordBBox cellRange(Coord(down(part.min().x(), 16), down(part.min().y(), 16),
                                                down(part.min().z(), 16)),
                                          part.max());
                for (int bx = down(part.min().x(), 32); bx <= part.max().x(); bx += 32)
                    for (int by = down(part.min().y(), 32); by <= part.max().y(); by += 32)
                        for (int bz = down(part.min().z(), 32); bz <= part.max().z(); bz += 32) {
                            for (int k = 0; k < 8; ++k) {
                                const Coord o(bx + ((k >> 2) & 1) * 16, by + ((k >> 1) & 1) * 16,
                                              bz + (k & 1) * 16);
                                if (!cellRange.isInside(o)) continue;
                                Cell cell{o, 0};
                                for (int m = 0; m < 8; ++m) {
                                    const Coord c = o.offsetBy(((m >> 2) & 1) * 8,
                                                               ((m >> 1) & 1) * 8, (m & 1) * 8);
                                    if (!leafRange.isInside(c)) continue;
                                    if (wanted && !(*wanted)(CoordBBox::createCube(c, 8))) continue;
                                    cell.leaves |= uint8_t(1u << m);
                                }
                                if (cell.leaves) perTop[ti].push_back(cell);
                            }
                        }
            }
        });
    std::vector<Cell> cells;
    for (const auto& v : perTop) cells.insert(cells.end(), v.begin(), v.end());
    if (cells.empty()) return;
    if (interrupter && interrupter->wasInterrupted(0)) throw Interrupted();

    // One scratch context per thread (its counters summed into stats at the end).
    tbb::enumerable_thread_specific<Context> contexts([&] {
        Context ctx;
        ctx.source = source;
        ctx.target = target;
        ctx.fn = &fn;
        return ctx;
    });

    // The candidate leaves, cell by cell.
    std::vector<Coord> candidates;
    auto expand = [&] {
        for (const Cell& cell : cells)
            for (int k = 0; k < 8; ++k)
                if (cell.leaves & (1u << k))
                    candidates.push_back(
                        cell.origin.offsetBy(((k >> 2) & 1) * 8, ((k >> 1) & 1) * 8, (k & 1) * 8));
    };

    // 2. The exact sums at the corners of the candidate leaves, each lattice point once. With
    //    occupancies, blocks of 2^3 cells and then cells are culled first from their own corners
    //    (every 4th, then every other lattice point), so that the leaves of a cell whose image
    //    misses both sides cost nothing.
    Lattice lattice;
    uint64_t latticeEvaluations = 0;
    std::atomic<bool> stopped{false};
    if (n > 0) {
        Coord llo(std::numeric_limits<int>::max()), lhi(std::numeric_limits<int>::min());
        for (const Cell& c : cells) { // the corners of their blocks of 32 voxels too
            const Coord l(c.origin.x() >> 3 & -4, c.origin.y() >> 3 & -4, c.origin.z() >> 3 & -4);
            llo = Coord::minComponent(llo, l);
            lhi = Coord::maxComponent(lhi, l.offsetBy(4));
        }
        lattice.lo = llo;
        lattice.dim = lhi - llo + Coord(1);
        lattice.count = size_t(lattice.dim.x()) * lattice.dim.y() * lattice.dim.z();
        lattice.points.reset(new LatticePoint[lattice.count]);
        // Each point is listed once, when first wanted, and evaluated by the next evaluate() (the
        // lists are not scanned for: the lattice's box is mostly unwanted).
        std::vector<char> wanted(lattice.count, 0);
        std::vector<size_t> pending;
        auto evaluate = [&](int progressFrom) {
            std::vector<size_t> todo;
            todo.swap(pending);
            latticeEvaluations += todo.size();
            tbb::parallel_for(
                tbb::blocked_range<size_t>(0, todo.size(), 64),
                [&](const tbb::blocked_range<size_t>& r) {
                    if (stopped ||
                        (interrupter && interrupter->wasInterrupted(
                                            progressFrom + int(5 * r.begin() / todo.size())))) {
                        stopped = true;
                        return;
                    }
                    const int yz = lattice.dim.y() * lattice.dim.z();
                    for (size_t i = r.begin(); i != r.end(); ++i) {
                        const size_t idx = todo[i];
                        const Coord l(lattice.lo.x() + int(idx / yz),
                                      lattice.lo.y() + int(idx % yz) / lattice.dim.z(),
                                      lattice.lo.z() + int(idx % lattice.dim.z()));
                        Lattice::Point& p = lattice.points[idx];
                        p.ok = exactSums(Vec3d(l.x() * 8.0, l.y() * 8.0, l.z() * 8.0), p);
                    }
                });
            if (stopped) throw Interrupted();
        };
        // Wants the corners of the cube of `step` lattice cells at origin; new ones go to `list`.
        // Safe from several threads at once (each point is claimed by one atomic exchange).
        auto want = [&](const Coord& origin, int step, std::vector<size_t>& list) {
            const Coord l(origin.x() >> 3, origin.y() >> 3, origin.z() >> 3);
            for (int k = 0; k < 8; ++k) {
                const size_t i = lattice.index(
                    l.offsetBy((k & 1) * step, ((k >> 1) & 1) * step, ((k >> 2) & 1) * step));
                if (!wanted[i] && __atomic_exchange_n(&wanted[i], char(1), __ATOMIC_RELAXED) == 0)
                    list.push_back(i);
            }
        };
        if (source || target) {
            // Blocks of 2^3 cells (32 voxels), then cells (16), each culled from its own corners.
            auto cull = [&](int size) {
                auto groupOf = [size](const Coord& c) {
                    return Coord(c.x() & -size, c.y() & -size, c.z() & -size);
                };
                std::vector<size_t> begin; // where each group's cells begin
                for (size_t i = 0; i < cells.size(); ++i)
                    if (i == 0 || groupOf(cells[i].origin) != groupOf(cells[i - 1].origin))
                        begin.push_back(i);
                begin.push_back(cells.size());
                const int step = size / 8;
                for (size_t g = 0; g + 1 < begin.size(); ++g)
                    want(groupOf(cells[begin[g]].origin), step, pending);
                evaluate(0);
                std::vector<char> keep(begin.size() - 1, 0);
                tbb::parallel_for(
                    tbb::blocked_range<size_t>(0, keep.size(), 8),
                    [&](const tbb::blocked_range<size_t>& r) {
                        Context& ctx = contexts.local();
                        for (size_t g = r.begin(); g != r.end(); ++g) {
                            const Coord o = groupOf(cells[begin[g]].origin);
                            const Coord l(o.x() >> 3, o.y() >> 3, o.z() >> 3);
                            const LatticePoint* corners[8];
                            for (int k = 0; k < 8; ++k)
                                corners[k] = &lattice.points[lattice.index(l.offsetBy(
                                    (k & 1) * step, ((k >> 1) & 1) * step, ((k >> 2) & 1) * step))];
                            analyze(ctx, corners, o, size);
                            keep[g] = mayTouch(ctx, o, size);
                        }
                    });
                size_t kept = 0;
                for (size_t g = 0; g < keep.size(); ++g)
                    if (keep[g])
                        for (size_t c = begin[g]; c < begin[g + 1]; ++c) cells[kept++] = cells[c];
                cells.resize(kept);
            };
            cull(32);
            cull(16);
        }
        expand();
        // The candidates' corners, found in parallel, listed in the threads' order (the points do
        // not depend on the order they are evaluated in).
        tbb::enumerable_thread_specific<std::vector<size_t>> found;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 512),
                          [&](const tbb::blocked_range<size_t>& r) {
                              std::vector<size_t>& list = found.local();
                              for (size_t i = r.begin(); i != r.end(); ++i)
                                  want(candidates[i], 1, list);
                          });
        for (const std::vector<size_t>& list : found)
            pending.insert(pending.end(), list.begin(), list.end());
        evaluate(5);
    } else {
        expand();
    }

    // 3. Every candidate leaf: culled by the bound, filled, culled by its points, handed on.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                          if (stopped ||
                              (interrupter && interrupter->wasInterrupted(
                                                  10 + int(90 * r.begin() / candidates.size())))) {
                              stopped = true;
                              return;
                          }
                          Context& ctx = contexts.local();
                          for (size_t i = r.begin(); i != r.end(); ++i)
                              leaf(ctx, lattice, candidates[i]);
                      });
    if (stopped) throw Interrupted();
    if (!stats) return;
    for (const Context& ctx : contexts) {
        stats->maxErrorVoxels = std::max(stats->maxErrorVoxels, ctx.maxError);
        stats->exactEvaluations += ctx.evaluations;
        stats->nearEvaluations += ctx.near;
        stats->allFarLeaves += ctx.allFar;
        stats->leaves += ctx.leaves;
    }
    stats->exactEvaluations += latticeEvaluations;
}

} // namespace volmorph::detail
