// The ray marcher. The only translation unit of render/ with OpenVDB's tools headers.
#include <volmorph/render/Renderer.h>

#include <openvdb/math/Ray.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/RayIntersector.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <unordered_map>

namespace volmorph::render {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using VdbRay = openvdb::math::Ray<double>;
using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::BoolGrid>;

/// Transmittance below this ends a ray: what is behind contributes less than 1e-4.
constexpr double kMinTransmittance = 1e-4;
const double kMaxOpticalDepth = -std::log(kMinTransmittance);

/// A counter-based generator: the same (pixel, sample, frame, seed) always gives the same numbers.
struct Random {
    uint64_t state;
    Random(uint64_t a, uint64_t b, uint64_t c)
    {
        state = mix(a * 0x9E3779B97F4A7C15ull ^ mix(b + 0x632BE59BD9B4E019ull) ^ mix(c + 0x85157AF5ull));
    }
    static uint64_t mix(uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double next()
    {
        state += 0x9E3779B97F4A7C15ull;
        return double(mix(state) >> 11) * (1.0 / 9007199254740992.0);
    }
};

double henyeyGreenstein(double cosTheta, double g)
{
    const double d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * d * std::sqrt(d));
}

/// Where a trilinear sample of `density` can be non-zero: its active voxels and tiles, dilated by one
/// voxel. (VolumeRayIntersector's own dilation ignores tiles, so a tile on a volume's boundary
/// would lose the half voxel of ramp outside it.)
openvdb::BoolGrid::Ptr rayMask(const FloatGrid& density, bool levelSet)
{
    openvdb::BoolGrid::Ptr mask = openvdb::BoolGrid::create(false);
    mask->setTransform(density.transform().copy());
    mask->tree().topologyUnion(density.tree());
    // A level set's interior is inactive (negative background): add it.
    if (levelSet) mask->tree().topologyUnion(openvdb::tools::sdfInteriorMask(density)->tree());
    openvdb::tools::dilateActiveValues(mask->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::PRESERVE_TILES);
    return mask;
}

/// Trilinear interpolation of eight colours at local coordinates u in [0, 1]^3.
inline Vec3d trilinear(const openvdb::Vec3s (&v)[2][2][2], const Vec3d& u)
{
    const double x1 = u.x(), y1 = u.y(), z1 = u.z(), x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
    const double w[8] = {x0 * y0 * z0, x0 * y0 * z1, x0 * y1 * z0, x0 * y1 * z1,
                         x1 * y0 * z0, x1 * y0 * z1, x1 * y1 * z0, x1 * y1 * z1};
    const openvdb::Vec3s* c = &v[0][0][0];
    double r = 0.0, g = 0.0, b = 0.0;
    for (int i = 0; i < 8; ++i) {
        r += w[i] * c[i].x();
        g += w[i] * c[i].y();
        b += w[i] * c[i].z();
    }
    return Vec3d(r, g, b);
}

/// The eight values at the corners of one interpolation cell [c, c + 1]^3 (voxel centres sit at
/// integer index coordinates) and OpenVDB's trilinear interpolant inside it (BoxSampler's).
struct Cell {
    float v[2][2][2];
    Coord origin;
    float lo, hi;       ///< smallest and largest corner value
    bool block = false; ///< one constant value over a whole block crossing (see walkCells)

    __attribute__((always_inline)) double at(const Vec3d& u) const // u: local coordinates in [0, 1]^3
    {
        const double x = u.x(), y = u.y(), z = u.z();
        const double a = v[0][0][0] + (v[0][0][1] - v[0][0][0]) * z;
        const double b = v[0][1][0] + (v[0][1][1] - v[0][1][0]) * z;
        const double c = v[1][0][0] + (v[1][0][1] - v[1][0][0]) * z;
        const double d = v[1][1][0] + (v[1][1][1] - v[1][1][0]) * z;
        const double e = a + (b - a) * y;
        const double f = c + (d - c) * y;
        return e + (f - e) * x;
    }
};

/// An index-space ray and the optical "mass" of a medium along it: the integral of density over a
/// piece [ta, tb] of the ray inside one cell, in voxels times density.
struct Medium1D {
    Vec3d eye, dir; ///< index space; dir has unit length, so ray times are in voxels
    bool levelSet;

    /// The integral of the density along [ta, tb] within `cell`. For a fog whose corners are all
    /// non-negative the trilinear interpolant is a cubic polynomial along the ray, integrated in
    /// closed form (Piece). A level set's density is 1 where the
    /// interpolated distance is negative: the length of that part, with each zero crossing placed
    /// by linear interpolation between the ends and the midpoint. A fog with negative corners
    /// (negative densities count as 0): the clamped value at four midpoints.
    double mass(const Cell& cell, double ta, double tb) const;
};

/// The density along one piece of a ray inside one cell, as a polynomial in s = t - ta (voxels), for
/// a fog whose corners are non-negative: the trilinear interpolant restricted to a line is a cubic.
/// mass(s) is its integral over [0, s]; exact is false for other cells (use Medium1D::mass).
struct Piece {
    bool exact = false;
    double c[4] = {0, 0, 0, 0};

    Piece(const Medium1D& ray, const Cell& cell, double ta)
    {
        if (ray.levelSet || cell.lo < 0.0f) return;
        exact = true;
        const Vec3d u = ray.eye + ray.dir * ta - Vec3d(cell.origin.x(), cell.origin.y(), cell.origin.z());
        const Vec3d& d = ray.dir;
        // Weights of the corners 0 and 1 along each axis, as linear functions w0 + w1 s.
        const double z[2][2] = {{1.0 - u.z(), -d.z()}, {u.z(), d.z()}};
        const double y[2][2] = {{1.0 - u.y(), -d.y()}, {u.y(), d.y()}};
        const double x[2][2] = {{1.0 - u.x(), -d.x()}, {u.x(), d.x()}};
        double h[2][3]; // along z, then y: a quadratic per x corner
        for (int i = 0; i < 2; ++i) {
            h[i][0] = h[i][1] = h[i][2] = 0.0;
            for (int j = 0; j < 2; ++j) {
                const double g0 = cell.v[i][j][0] * z[0][0] + cell.v[i][j][1] * z[1][0];
                const double g1 = cell.v[i][j][0] * z[0][1] + cell.v[i][j][1] * z[1][1];
                h[i][0] += g0 * y[j][0];
                h[i][1] += g0 * y[j][1] + g1 * y[j][0];
                h[i][2] += g1 * y[j][1];
            }
        }
        for (int i = 0; i < 2; ++i) {
            c[0] += h[i][0] * x[i][0];
            c[1] += h[i][0] * x[i][1] + h[i][1] * x[i][0];
            c[2] += h[i][1] * x[i][1] + h[i][2] * x[i][0];
            c[3] += h[i][2] * x[i][1];
        }
    }

    double mass(double s) const { return s * (c[0] + s * (0.5 * c[1] + s * (c[2] * (1.0 / 3.0) + s * 0.25 * c[3]))); }
};

double Medium1D::mass(const Cell& cell, double ta, double tb) const
{
    const double length = tb - ta;
    const Vec3d base = eye - Vec3d(cell.origin.x(), cell.origin.y(), cell.origin.z());
    auto local = [&](double t) { return base + dir * t; };
    if (!levelSet) {
        if (cell.hi <= 0.0f) return 0.0;
        if (cell.lo >= 0.0f) return Piece(*this, cell, ta).mass(length);
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) sum += std::max(0.0, cell.at(local(ta + (k + 0.5) * 0.25 * length)));
        return 0.25 * length * sum;
    }
    if (cell.lo >= 0.0f) return 0.0;
    if (cell.hi < 0.0f) return length;
    const double f0 = cell.at(local(ta)), f1 = cell.at(local(0.5 * (ta + tb))), f2 = cell.at(local(tb));
    auto inside = [](double a, double b, double h) { // length of the negative part of a linear piece
        if (a < 0.0 && b < 0.0) return h;
        if (a >= 0.0 && b >= 0.0) return 0.0;
        const double crossing = a / (a - b) * h; // from the start
        return a < 0.0 ? crossing : h - crossing;
    };
    return inside(f0, f1, 0.5 * length) + inside(f1, f2, 0.5 * length);
}

/// e^-x for x >= 0; a short series where x is small (the common case of one step of a thin medium,
/// relative error below 1e-10 for x < 0.05).
inline double expNegative(double x)
{
    constexpr double third = 1.0 / 3.0, sixth = 1.0 / 6.0;
    if (x < 0.05) return 1.0 - x * (1.0 - x * 0.5 * (1.0 - x * third * (1.0 - x * 0.25 * (1.0 - x * 0.2 * (1.0 - x * sixth)))));
    return std::exp(-x);
}

/// Each leaf's values plus one more layer on its +x, +y and +z sides (read from the neighbours):
/// the eight corners of every cell whose origin lies in the leaf, so that reading them is eight
/// loads, also for cells that straddle two, four or eight leaves. A leaf whose 512 values are equal
/// is left out: readers treat it as a tile of that value (interpolation reads values, never active
/// states), which walkCells crosses in one piece.
class PaddedLeaves
{
public:
    using Leaf = openvdb::FloatTree::LeafNodeType;
    static constexpr int kSide = Leaf::DIM + 1, kSize = kSide * kSide * kSide;

    explicit PaddedLeaves(const openvdb::FloatTree& tree)
    {
        std::vector<const Leaf*> leaves;
        leaves.reserve(tree.leafCount());
        for (auto it = tree.cbeginLeaf(); it; ++it) {
            const float* d = it->buffer().data();
            if (!std::all_of(d + 1, d + Leaf::SIZE, [d](float v) { return v == d[0]; })) leaves.push_back(&*it);
        }
        mValues.resize(leaves.size() * kSize);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
            openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(tree);
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const Leaf& leaf = *leaves[i];
                const float* d = leaf.buffer().data();
                float* out = &mValues[i * kSize];
                for (int x = 0; x < kSide; ++x)
                    for (int y = 0; y < kSide; ++y)
                        for (int z = 0; z < kSide; ++z)
                            out[(x * kSide + y) * kSide + z] = x < 8 && y < 8 && z < 8
                                ? d[(x << 6) | (y << 3) | z]
                                : acc.getValue(leaf.origin().offsetBy(x, y, z));
            }
        });
        mIndex.reserve(leaves.size());
        for (size_t i = 0; i < leaves.size(); ++i) mIndex.emplace(leaves[i], &mValues[i * kSize]);
    }

    const float* find(const Leaf* leaf) const
    {
        const auto it = mIndex.find(leaf);
        return it == mIndex.end() ? nullptr : it->second;
    }

private:
    std::vector<float> mValues;
    std::unordered_map<const Leaf*, const float*> mIndex;
};

/// One thread's trilinear reader of a colour grid, remembering the last 8^3 block: inside a block
/// without a leaf the colour is its tile value, inside a leaf the corners are read from its buffer.
struct ColorReader {
    using Tree = openvdb::Vec3STree;
    using Leaf = Tree::LeafNodeType;
    openvdb::tree::ValueAccessor<const Tree> acc;
    Coord block{std::numeric_limits<int>::max()};
    const Leaf* leaf = nullptr;
    openvdb::Vec3s tile;

    explicit ColorReader(const Tree& tree) : acc(tree) {}

    Vec3d at(const Vec3d& ip)
    {
        const Coord c = Coord::floor(ip);
        const Coord b(c.x() & ~7, c.y() & ~7, c.z() & ~7);
        if (b != block) {
            block = b;
            leaf = acc.probeConstLeaf(c);
            if (!leaf) tile = acc.getValue(c);
        }
        openvdb::Vec3s v[2][2][2];
        if ((c.x() & 7) != 7 && (c.y() & 7) != 7 && (c.z() & 7) != 7) {
            if (!leaf) return Vec3d(tile.x(), tile.y(), tile.z());
            const openvdb::Vec3s* d = leaf->buffer().data() + Leaf::coordToOffset(c);
            v[0][0][0] = d[0];   v[0][0][1] = d[1];
            v[0][1][0] = d[8];   v[0][1][1] = d[9];
            v[1][0][0] = d[64];  v[1][0][1] = d[65];
            v[1][1][0] = d[72];  v[1][1][1] = d[73];
        } else {
            openvdb::tools::BoxSampler::getValues(v, acc, c);
        }
        return trilinear(v, ip - Vec3d(c.x(), c.y(), c.z()));
    }
};

/// One thread's reader of a cell's eight density values: the padded copy of the cell's leaf, or the
/// one value of a block that has none (a tile, the background, or a constant leaf).
struct DensityReader {
    openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc;
    const PaddedLeaves& padded;
    /// A direct-mapped cache of 8^3 blocks: a block's padded values, or its one value if it has
    /// none.
    struct Block {
        Coord origin{std::numeric_limits<int>::max()};
        const float* values = nullptr;
        float tile = 0.0f;
    };
    Block cache[64];
    float tile = 0.0f; ///< the value of the last cell's block, when cell() returned false

    DensityReader(const openvdb::FloatTree& tree, const PaddedLeaves& p) : acc(tree), padded(p) {}

    const Block& blockAt(const Coord& b) // b: a block origin (multiples of 8)
    {
        Block& e = cache[((b.x() >> 3) & 3) | (((b.y() >> 3) & 3) << 2) | (((b.z() >> 3) & 3) << 4)];
        if (e.origin != b) {
            e.origin = b;
            const PaddedLeaves::Leaf* leaf = acc.probeConstLeaf(b);
            e.values = leaf ? padded.find(leaf) : nullptr;
            if (!e.values) e.tile = acc.getValue(b);
        }
        return e;
    }

    /// Fills `v` for the cell at `c` and returns true, or returns false (filling nothing, `tile` set)
    /// if c's block has one value and c lies inside it (not on its +x, +y or +z face layer).
    bool cell(const Coord& c, float (&v)[2][2][2])
    {
        const Coord b(c.x() & ~7, c.y() & ~7, c.z() & ~7);
        const Block& own = blockAt(b);
        if (own.values) {
            constexpr int s = PaddedLeaves::kSide;
            const float* p = own.values + ((c.x() & 7) * s + (c.y() & 7)) * s + (c.z() & 7);
            v[0][0][0] = p[0];         v[0][0][1] = p[1];
            v[0][1][0] = p[s];         v[0][1][1] = p[s + 1];
            v[1][0][0] = p[s * s];     v[1][0][1] = p[s * s + 1];
            v[1][1][0] = p[s * s + s]; v[1][1][1] = p[s * s + s + 1];
            return true;
        }
        tile = own.tile;
        const int edge[3] = {(c.x() & 7) == 7, (c.y() & 7) == 7, (c.z() & 7) == 7};
        if (!edge[0] && !edge[1] && !edge[2]) return false;
        // A cell straddling blocks: each corner from its own block (a tile value, or a leaf value).
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j)
                for (int k = 0; k < 2; ++k) {
                    const Coord corner = c.offsetBy(i, j, k);
                    const Block& e = blockAt(Coord(corner.x() & ~7, corner.y() & ~7, corner.z() & ~7));
                    v[i][j][k] = e.values ? acc.getValue(corner) : e.tile;
                }
        return true;
    }
};

/// Walks the interpolation cells that the index ray eye + t dir crosses for t in [ta, tb]
/// (Amanatides and Woo's 3D DDA), calling visit(cell, t0, t1) for each piece whose cell has a
/// non-zero density somewhere; stops early when visit returns false. Returns false if stopped.
/// Where the ray enters an 8^3 block of one value (a tile, the background, a constant leaf), every
/// cell within the block's [b, b + 7]^3 is constant: the whole crossing is one piece. Consecutive
/// pieces of one constant density (such blocks, cells of one value, level-set cells wholly inside)
/// are visited as one piece marked Cell::block.
template <typename Visit>
bool walkCells(DensityReader& reader, const Medium1D& ray, double ta, double tb, Visit&& visit)
{
    int cell[3], step[3];
    double next[3], delta[3];
    Cell c, run;
    bool pending = false; // a run of constant pieces not yet visited: [runStart, pendingEnd]
    double runStart = 0.0, pendingEnd = 0.0;
    float pendingRho = 0.0f;
    double t = ta;
    while (t < tb) {
        const Vec3d start = ray.eye + ray.dir * t;
        for (int a = 0; a < 3; ++a) {
            cell[a] = int(std::floor(start[a]));
            const double d = ray.dir[a];
            if (d > 0.0) {
                step[a] = 1;
                delta[a] = 1.0 / d;
                next[a] = t + (cell[a] + 1 - start[a]) * delta[a];
            } else if (d < 0.0) {
                step[a] = -1;
                delta[a] = -1.0 / d;
                next[a] = t + (start[a] - cell[a]) * delta[a];
            } else {
                step[a] = 0;
                delta[a] = std::numeric_limits<double>::infinity();
                next[a] = std::numeric_limits<double>::infinity();
            }
        }
        bool restart = false;
        while (t < tb && !restart) {
            const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
            double t1 = std::min(next[a], tb);
            c.origin = Coord(cell[0], cell[1], cell[2]);
            c.block = false;
            if (!reader.cell(c.origin, c.v)) {
                {
                    const float value = reader.tile;
                    for (int i = 0; i < 8; ++i) (&c.v[0][0][0])[i] = value;
                    // Where the ray leaves the block's constant region [b, b + 7]^3.
                    double exit = tb;
                    for (int k = 0; k < 3; ++k) {
                        const double d = ray.dir[k];
                        if (d == 0.0) continue;
                        const double lo = double(cell[k] & ~7), wall = d > 0.0 ? lo + 7.0 : lo;
                        exit = std::min(exit, (wall - ray.eye[k]) / d);
                    }
                    if (exit > t1 + 1e-6) {
                        t1 = exit;
                        c.block = true;
                        restart = true;
                    }
                }
            }
            if (t1 > t) {
                openvdb::tools::BoxSampler::extrema(c.v, c.lo, c.hi);
                const bool empty = ray.levelSet ? c.lo >= 0.0f : c.hi <= 0.0f;
                // Constant density along the piece: a fog cell of one value, a level-set cell
                // wholly inside.
                const bool constant = c.block || (ray.levelSet ? c.hi < 0.0f : c.lo == c.hi);
                const float rho = ray.levelSet ? 1.0f : c.hi;
                if (pending && !(constant && !empty && rho == pendingRho && t == pendingEnd)) {
                    pending = false;
                    if (!visit(run, runStart, pendingEnd)) return false;
                }
                if (constant && !empty) {
                    // Runs of constant pieces of one density are visited as one piece.
                    if (!pending) {
                        pending = true;
                        run = c;
                        run.block = true;
                        runStart = t;
                        pendingRho = rho;
                    }
                    pendingEnd = t1;
                } else if (!empty && !visit(c, t, t1)) {
                    return false;
                }
            }
            t = t1;
            if (!restart) {
                cell[a] += step[a];
                next[a] += delta[a];
            }
        }
    }
    return !pending || visit(run, runStart, pendingEnd);
}

/// Optical depth (index units times sigma) from world point p along `direction` for up to
/// `distance` world units, integrated cell by cell.
double opticalDepth(Intersector& inter, bool levelSet, DensityReader& acc,
                    const Vec3d& p, const Vec3d& direction, double distance, double sigmaPerVoxel)
{
    if (!inter.setWorldRay(VdbRay(p, direction, 0.0, distance))) return 0.0;
    Medium1D ray{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0), levelSet};
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    while (inter.march(t0, t1)) {
        const bool going = walkCells(acc, ray, t0, t1, [&](const Cell& cell, double ta, double tb) {
            tau += sigmaPerVoxel * ray.mass(cell, ta, tb);
            return tau <= kMaxOpticalDepth + 2.0;
        });
        if (!going) break;
    }
    return tau;
}

/// Transmittance toward a point light, on a coarse grid over the occupied region: one march toward
/// the light per grid point, sampled trilinearly.
FloatGrid::Ptr pointLightCache(const FloatGrid& density, const PaddedLeaves& padded, const openvdb::BoolGrid& mask, bool levelSet,
                               const Light& light, double sigmaPerVoxel, const RenderSettings& settings)
{
    const int factor = std::max(1, settings.shadowCacheVoxels);
    const double voxel = density.voxelSize()[0];
    FloatGrid::Ptr cache = FloatGrid::create(1.0f);
    cache->setTransform(openvdb::math::Transform::createLinearTransform(voxel * factor));
    auto coarse = [factor](const Coord& c) {
        auto f = [factor](int v) { return v >= 0 ? v / factor : -((-v + factor - 1) / factor); };
        return Coord(f(c.x()), f(c.y()), f(c.z()));
    };
    for (auto leaf = mask.tree().cbeginLeaf(); leaf; ++leaf) {
        const CoordBBox b = leaf->getNodeBoundingBox();
        cache->tree().fill(CoordBBox(coarse(b.min()), coarse(b.max())), 1.0f, true);
    }
    auto tiles = mask.tree().cbeginValueOn();
    tiles.setMaxDepth(openvdb::BoolTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        const CoordBBox b = tiles.getBoundingBox();
        cache->tree().fill(CoordBBox(coarse(b.min()), coarse(b.max())), 1.0f, true);
    }
    openvdb::tools::dilateActiveValues(cache->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    cache->tree().voxelizeActiveTiles();

    const Intersector master(mask);
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(cache->tree());
    leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
        Intersector inter(master);
        DensityReader acc(density.tree(), padded);
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const Vec3d p = cache->indexToWorld(it.getCoord());
            Vec3d toward = light.position - p;
            const double distance = toward.length();
            if (distance <= 0.0) continue;
            toward /= distance;
            it.setValue(float(std::exp(-opticalDepth(inter, levelSet, acc, p, toward, distance, sigmaPerVoxel))));
        }
    });
    return cache;
}

/// Transmittance toward a directional light: a deep shadow map (Lokovic and Veach). A lattice of
/// columns parallel to the light, `spacing` world units apart, each marched once through the
/// volume cell by cell, keeping the transmittance every `spacing` along it; looked up by bilinear
/// interpolation across columns and linear along them. Only the span of each column that crosses
/// the occupied region is stored.
class ShadowMap
{
public:
    ShadowMap(const FloatGrid& density, const PaddedLeaves& padded, const openvdb::BoolGrid& mask, bool levelSet, const Vec3d& travel,
              double sigmaPerVoxel, double spacing)
        : mDensity(density), mSpacing(spacing)
    {
        mW = travel.unit();
        mU = (std::abs(mW.x()) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0)).cross(mW).unit();
        mV = mW.cross(mU);
        const CoordBBox box = mask.evalActiveVoxelBoundingBox();
        Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
        for (int i = 0; i < 8; ++i) {
            const Vec3d corner((i & 1) ? box.max().x() + 1.0 : box.min().x() - 1.0,
                               (i & 2) ? box.max().y() + 1.0 : box.min().y() - 1.0,
                               (i & 4) ? box.max().z() + 1.0 : box.min().z() - 1.0);
            const Vec3d w = density.indexToWorld(corner);
            const Vec3d l(w.dot(mU), w.dot(mV), w.dot(mW));
            lo = openvdb::math::minComponent(lo, l);
            hi = openvdb::math::maxComponent(hi, l);
        }
        mOrigin = lo - Vec3d(spacing);
        // For a linear transform, the lattice coordinates are an affine function of index space.
        mLinear = density.transform().isLinear();
        if (mLinear) {
            const Vec3d w0 = density.indexToWorld(Vec3d(0.0));
            const Vec3d ex = density.indexToWorld(Vec3d(1, 0, 0)) - w0, ey = density.indexToWorld(Vec3d(0, 1, 0)) - w0,
                        ez = density.indexToWorld(Vec3d(0, 0, 1)) - w0;
            const Vec3d* axes[3] = {&mU, &mV, &mW};
            for (int r = 0; r < 3; ++r) {
                mRow[r] = Vec3d(ex.dot(*axes[r]), ey.dot(*axes[r]), ez.dot(*axes[r])) / spacing;
                mOffset[r] = (w0.dot(*axes[r]) - mOrigin[r]) / spacing;
            }
        }
        mCount[0] = int(std::ceil((hi.x() - mOrigin.x()) / spacing)) + 2;
        mCount[1] = int(std::ceil((hi.y() - mOrigin.y()) / spacing)) + 2;
        const double length = hi.z() - mOrigin.z() + 2.0 * spacing;
        const size_t columns = size_t(mCount[0]) * size_t(mCount[1]);
        std::vector<Column> columnsBuilt(columns);

        const Intersector master(mask);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, columns, 64), [&](const tbb::blocked_range<size_t>& range) {
            Intersector inter(master);
            DensityReader acc(density.tree(), padded);
            for (size_t c = range.begin(); c != range.end(); ++c) {
                const int i = int(c % size_t(mCount[0])), j = int(c / size_t(mCount[0]));
                const Vec3d start = mU * (mOrigin.x() + i * spacing) + mV * (mOrigin.y() + j * spacing) +
                                    mW * mOrigin.z();
                march(inter, acc, levelSet, start, length, sigmaPerVoxel, columnsBuilt[c]);
            }
        });
        // One contiguous array for lookups.
        size_t total = 0;
        for (const Column& c : columnsBuilt) total += c.values.size();
        mData.reserve(total);
        mSpans.resize(columns);
        for (size_t c = 0; c < columns; ++c) {
            const Column& col = columnsBuilt[c];
            mSpans[c] = Span{col.first, int(col.values.size()), col.last, uint32_t(mData.size())};
            mData.insert(mData.end(), col.values.begin(), col.values.end());
        }
    }

    /// Transmittance toward the light at index point ip of the density grid.
    double lookup(const Vec3d& ip) const
    {
        double a, b, c;
        if (mLinear) {
            a = mRow[0].dot(ip) + mOffset.x();
            b = mRow[1].dot(ip) + mOffset.y();
            c = mRow[2].dot(ip) + mOffset.z();
        } else {
            const Vec3d p = mDensity.indexToWorld(ip);
            a = (p.dot(mU) - mOrigin.x()) / mSpacing;
            b = (p.dot(mV) - mOrigin.y()) / mSpacing;
            c = (p.dot(mW) - mOrigin.z()) / mSpacing;
        }
        const double fa = std::floor(a), fb = std::floor(b), fc = std::floor(c);
        const int i = int(fa), j = int(fb), k = int(fc);
        const double u = a - fa, v = b - fb, w = c - fc;
        auto column = [&](int ci, int cj) __attribute__((always_inline)) {
            if (ci < 0 || cj < 0 || ci >= mCount[0] || cj >= mCount[1]) return 1.0;
            const Span& span = mSpans[size_t(cj) * size_t(mCount[0]) + size_t(ci)];
            const float* data = mData.data() + span.offset;
            auto at = [&](int kk) {
                const int i = kk - span.first;
                return i < 0 ? 1.0 : i < span.count ? double(data[i]) : double(span.last);
            };
            return (1.0 - w) * at(k) + w * at(k + 1);
        };
        return (1.0 - v) * ((1.0 - u) * column(i, j) + u * column(i + 1, j)) +
               v * ((1.0 - u) * column(i, j + 1) + u * column(i + 1, j + 1));
    }

private:
    struct Column {
        int first = 0;           ///< lattice index of values[0]; before it the transmittance is 1
        float last = 1.0f;       ///< the transmittance after the stored span
        std::vector<float> values;
        double at(int k) const
        {
            if (k < first) return 1.0;
            const size_t i = size_t(k - first);
            return i < values.size() ? double(values[i]) : double(last);
        }
    };

    void march(Intersector& inter, DensityReader& acc, bool levelSet,
               const Vec3d& start, double length, double sigmaPerVoxel, Column& column) const
    {
        if (!inter.setWorldRay(VdbRay(start, mW, 0.0, length))) return;
        const Medium1D ray{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0), levelSet};
        // Index time per lattice step (the index ray has unit speed in voxels).
        const double h = inter.getWorldTime(1.0) > 0.0 ? mSpacing / inter.getWorldTime(1.0) : mSpacing;
        double tau = 0.0, t0 = 0.0, t1 = 0.0;
        int k = -1; // the last lattice index stored
        auto push = [&] { column.values.push_back(float(std::exp(-tau))); ++k; };
        bool going = true;
        while (going && inter.march(t0, t1)) {
            if (k < 0) { // nothing is absorbed before the first span: the column starts there
                column.first = int(std::floor(t0 / h));
                k = column.first - 1;
            }
            going = walkCells(acc, ray, t0, t1, [&](const Cell& cell, double ta, double tb) {
                // Split the piece at the lattice points inside it.
                for (double tk = (k + 1) * h; tk <= tb; tk = (k + 1) * h) {
                    if (tk > ta) {
                        tau += sigmaPerVoxel * ray.mass(cell, ta, tk);
                        ta = tk;
                    }
                    push();
                }
                tau += sigmaPerVoxel * ray.mass(cell, ta, tb);
                return tau <= kMaxOpticalDepth + 2.0;
            });
            while ((k + 1) * h <= t1) push();
        }
        column.last = float(std::exp(-tau));
    }

    const FloatGrid& mDensity;
    Vec3d mU, mV, mW, mOrigin; ///< light frame; origin in its coordinates (world units)
    double mSpacing;
    bool mLinear = false;
    Vec3d mRow[3], mOffset;    ///< index space to lattice coordinates, for a linear transform
    int mCount[2];
    struct Span {         ///< a column in mData
        int first, count; ///< lattice index of its first value, and how many
        float last;       ///< the transmittance past its last value
        uint32_t offset;
    };
    std::vector<Span> mSpans;
    std::vector<float> mData;
};

/// One light's shadow: a deep shadow map for a directional light, a grid of marches for a point light.
struct Shadow {
    std::unique_ptr<ShadowMap> map;
    FloatGrid::Ptr cache;
};

} // namespace

Image renderVolume(const FloatGrid& density, const openvdb::Vec3SGrid* color, const Camera& camera,
                   const std::vector<Light>& lights, const Medium& medium, const RenderSettings& settings)
{
    Image image;
    image.width = camera.width();
    image.height = camera.height();
    image.pixels.assign(size_t(image.width) * size_t(image.height) * 4, 0.0f);
    const bool levelSet = medium.kind == Medium::Kind::LevelSet;
    if (density.tree().activeVoxelCount() == 0) return image;

    const double voxel = density.voxelSize()[0];
    const double sigmaPerVoxel = medium.extinction * voxel; // per index unit
    const int samples = std::max(1, settings.samples);
    const int strata = int(std::ceil(std::sqrt(double(samples))));
    const double inverseFactor = 1.0 / double(std::max(1, settings.shadowCacheVoxels));
    const double h = settings.stepVoxels > 0.0 ? settings.stepVoxels : 0.5;

    auto body = [&] {
        const openvdb::BoolGrid::Ptr mask = rayMask(density, levelSet);
        const PaddedLeaves padded(density.tree());
        std::vector<Shadow> shadows(lights.size());
        for (size_t l = 0; l < lights.size(); ++l) {
            if (lights[l].type == Light::Type::Directional)
                shadows[l].map = std::make_unique<ShadowMap>(density, padded, *mask, levelSet, lights[l].direction,
                    sigmaPerVoxel, voxel * std::max(1, settings.shadowCacheVoxels));
            else
                shadows[l].cache = pointLightCache(density, padded, *mask, levelSet, lights[l], sigmaPerVoxel, settings);
        }
        const Intersector master(*mask);
        tbb::parallel_for(tbb::blocked_range2d<int>(0, image.height, 16, 0, image.width, 16),
                          [&](const tbb::blocked_range2d<int>& tile) {
            Intersector inter(master);
            DensityReader acc(density.tree(), padded);
            std::unique_ptr<ColorReader> colors;
            if (color) colors = std::make_unique<ColorReader>(color->tree());
            std::vector<std::unique_ptr<openvdb::tree::ValueAccessor<const openvdb::FloatTree>>> cacheAcc(lights.size());
            for (size_t l = 0; l < lights.size(); ++l)
                if (shadows[l].cache)
                    cacheAcc[l] = std::make_unique<openvdb::tree::ValueAccessor<const openvdb::FloatTree>>(shadows[l].cache->tree());
            std::vector<Vec3d> perRay(lights.size());
            for (int y = tile.rows().begin(); y != tile.rows().end(); ++y) {
                for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
                    double r = 0, g = 0, b = 0, alpha = 0;
                    for (int s = 0; s < samples; ++s) {
                        Random random(uint64_t(y) * 65536u + uint64_t(x), uint64_t(s), (uint64_t(settings.frame) << 32) ^ settings.seed);
                        // One sample goes through the pixel centre (no antialiasing, as vdb_render);
                        // more are stratified and jittered over the pixel.
                        const double jx = random.next(), jy = random.next();
                        const double sx = samples == 1 ? 0.5 : ((s % strata) + jx) / strata;
                        const double sy = samples == 1 ? 0.5 : ((s / strata) % strata + jy) / strata;
                        const Ray ray = camera.ray(x + sx, y + sy);
                        double T = 1.0;
                        Vec3d L(0.0);
                        if (inter.setWorldRay(VdbRay(ray.origin, ray.direction))) {
                            // A directional light's phase and colour are constant along a ray.
                            for (size_t l = 0; l < lights.size(); ++l) {
                                const Light& light = lights[l];
                                perRay[l] = light.color * (light.intensity *
                                    henyeyGreenstein(light.direction.unit().dot(-ray.direction), medium.anisotropy));
                            }
                            const Medium1D line{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0), levelSet};
                            // Each piece of the ray inside one interpolation cell (or constant block) is
                            // cut into equal steps of at most h voxels. Each step's optical depth is
                            // exact (the integral of the trilinear density, see Piece). The source S
                            // (emission plus albedo times the light reaching the point) is evaluated at
                            // knots along the ray, at the first step end at least one voxel after the
                            // previous knot (so 1 to 1 + h voxels apart), and taken linearly in between:
                            // each step adds a = T (1 - e^-tau) times S at its middle. A and B sum a and
                            // a (t - knot) until the next knot, which closes them.
                            auto sourceAt = [&](double t) {
                                const Vec3d ip = line.eye + line.dir * t;
                                Vec3d albedo(medium.albedo);
                                if (colors) albedo = colors->at(ip) * medium.albedo;
                                Vec3d source = medium.emission;
                                for (size_t l = 0; l < lights.size(); ++l) {
                                    const Light& light = lights[l];
                                    Vec3d c = perRay[l];
                                    double Tl;
                                    if (light.type == Light::Type::Point) {
                                        Vec3d travel = density.indexToWorld(ip) - light.position;
                                        const double d2 = travel.lengthSqr();
                                        travel /= std::sqrt(d2);
                                        c = light.color * (light.intensity / d2 *
                                            henyeyGreenstein(travel.dot(-ray.direction), medium.anisotropy));
                                        // The cache shares the density's origin, at `factor` times its voxel.
                                        Tl = openvdb::tools::BoxSampler::sample(*cacheAcc[l], ip * inverseFactor);
                                    } else {
                                        Tl = shadows[l].map->lookup(ip);
                                    }
                                    source += Vec3d(albedo.x() * c.x(), albedo.y() * c.y(), albedo.z() * c.z()) * Tl;
                                }
                                return source;
                            };
                            bool open = false;     // a knot is placed and steps since it are pending
                            double knot = 0.0, A = 0.0, B = 0.0, lastEnd = -1.0;
                            Vec3d knotSource(0.0);
                            auto close = [&](double t) { // a knot at t: settle the steps since the last
                                const Vec3d next = sourceAt(t);
                                if (A > 0.0) L += knotSource * A + (next - knotSource) * (t > knot ? B / (t - knot) : 0.0);
                                knot = t;
                                knotSource = next;
                                A = B = 0.0;
                            };
                            // Steps of one piece [ta, tb]: n steps of length dt, optical depth from tauOf.
                            auto march = [&](double ta, double tb, int n, auto&& tauOf) {
                                if (!open || ta != lastEnd) { // a gap: settle the run before it
                                    if (open) close(lastEnd);
                                    knot = ta;
                                    knotSource = sourceAt(ta);
                                    A = B = 0.0;
                                    open = true;
                                }
                                const double dt = (tb - ta) / n;
                                double lastTau = -1.0, transmitted = 1.0;
                                for (int k = 0; k < n; ++k) {
                                    const double tau = tauOf(k, dt);
                                    const double end = k + 1 == n ? tb : ta + (k + 1) * dt;
                                    if (tau > 0.0) {
                                        if (tau != lastTau) { // equal steps of a constant piece: once
                                            lastTau = tau;
                                            transmitted = expNegative(tau);
                                        }
                                        const double a = T * (1.0 - transmitted);
                                        A += a;
                                        B += a * (end - 0.5 * dt - knot);
                                        T *= transmitted;
                                    }
                                    if (T <= kMinTransmittance) {
                                        close(end);
                                        open = false;
                                        return false;
                                    }
                                    if (end - knot >= 1.0) close(end);
                                }
                                lastEnd = tb;
                                return true;
                            };
                            auto shade = [&](const Cell& cell, double ta, double tb) {
                                const int n = std::max(1, int(std::ceil((tb - ta) / h - 1e-9)));
                                if (cell.block) {
                                    const double rho = levelSet ? (cell.lo < 0.0f ? 1.0 : 0.0) : double(cell.hi);
                                    return march(ta, tb, n, [&](int, double dt) { return sigmaPerVoxel * rho * dt; });
                                }
                                const Piece piece(line, cell, ta);
                                double before = 0.0; // piece.mass at the start of step k
                                return march(ta, tb, n, [&](int k, double dt) {
                                    if (!piece.exact) return sigmaPerVoxel * line.mass(cell, ta + k * dt, ta + (k + 1) * dt);
                                    const double after = piece.mass((k + 1) * dt);
                                    const double tau = sigmaPerVoxel * (after - before);
                                    before = after;
                                    return tau;
                                });
                            };
                            double t0 = 0, t1 = 0;
                            while (inter.march(t0, t1) && walkCells(acc, line, t0, t1, shade)) {}
                            if (open) close(lastEnd);
                        }
                        r += L.x();
                        g += L.y();
                        b += L.z();
                        alpha += 1.0 - T;
                    }
                    float* px = image.at(x, y);
                    px[0] = float(r / samples);
                    px[1] = float(g / samples);
                    px[2] = float(b / samples);
                    px[3] = float(alpha / samples);
                }
            }
        });
    };
    if (settings.threads > 0) tbb::task_arena(settings.threads).execute(body);
    else body();
    return image;
}

} // namespace volmorph::render
