#include "Shadows.h"

#include "CellWalk.h"

#include <openvdb/tools/Morphology.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace volmorph::render {

using openvdb::CoordBBox;
using openvdb::FloatGrid;

/// Optical depth (index units times sigma) from world point p along `direction` for up to
/// `distance` world units, integrated cell by cell.
double opticalDepth(Intersector& inter, bool levelSet, DensityReader& acc, const Vec3d& p,
                    const Vec3d& direction, double distance, double sigmaPerVoxel)
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

namespace {

/// Transmittance toward a point light, on a coarse grid over the occupied region: one march toward
/// the light per grid point, sampled trilinearly.
FloatGrid::Ptr pointLightCache(const FloatGrid& density, const PaddedLeaves& padded,
                               const openvdb::BoolGrid& mask, bool levelSet, const Light& light,
                               double sigmaPerVoxel, int shadowCacheVoxels,
                               openvdb::util::NullInterrupter* interrupter)
{
    const int factor = std::max(1, shadowCacheVoxels);
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
    openvdb::tools::dilateActiveValues(cache->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    cache->tree().voxelizeActiveTiles();

    const Intersector master(mask);
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(cache->tree());
    leaves.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
        if (interrupter && interrupter->wasInterrupted()) return;
        Intersector inter(master);
        DensityReader acc(density.tree(), padded);
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const Vec3d p = cache->indexToWorld(it.getCoord());
            Vec3d toward = light.position - p;
            const double distance = toward.length();
            if (distance <= 0.0) continue;
            toward /= distance;
            it.setValue(float(
                std::exp(-opticalDepth(inter, levelSet, acc, p, toward, distance, sigmaPerVoxel))));
        }
    });
    return cache;
}

} // namespace

ShadowMap::ShadowMap(const FloatGrid& density, const PaddedLeaves& padded,
                     const openvdb::BoolGrid& mask, bool levelSet, const Vec3d& travel,
                     double sigmaPerVoxel, double spacing,
                     openvdb::util::NullInterrupter* interrupter)
    : mDensity(density), mSpacing(spacing)
{
    const double length = placeLattice(density, mask, travel);
    std::vector<Column> columns(size_t(mCount[0]) * size_t(mCount[1]));
    marchColumns(density, padded, mask, levelSet, length, sigmaPerVoxel, interrupter, columns);
    pack(columns);
}

double ShadowMap::placeLattice(const FloatGrid& density, const openvdb::BoolGrid& mask,
                               const Vec3d& travel)
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
    mOrigin = lo - Vec3d(mSpacing);
    // For a linear transform, the lattice coordinates are an affine function of index space.
    mLinear = density.transform().isLinear();
    if (mLinear) {
        const Vec3d w0 = density.indexToWorld(Vec3d(0.0));
        const Vec3d ex = density.indexToWorld(Vec3d(1, 0, 0)) - w0,
                    ey = density.indexToWorld(Vec3d(0, 1, 0)) - w0,
                    ez = density.indexToWorld(Vec3d(0, 0, 1)) - w0;
        const Vec3d* axes[3] = {&mU, &mV, &mW};
        for (int r = 0; r < 3; ++r) {
            mRow[r] = Vec3d(ex.dot(*axes[r]), ey.dot(*axes[r]), ez.dot(*axes[r])) / mSpacing;
            mOffset[r] = (w0.dot(*axes[r]) - mOrigin[r]) / mSpacing;
        }
    }
    mCount[0] = int(std::ceil((hi.x() - mOrigin.x()) / mSpacing)) + 2;
    mCount[1] = int(std::ceil((hi.y() - mOrigin.y()) / mSpacing)) + 2;
    return hi.z() - mOrigin.z() + 2.0 * mSpacing;
}

void ShadowMap::marchColumns(const FloatGrid& density, const PaddedLeaves& padded,
                             const openvdb::BoolGrid& mask, bool levelSet, double length,
                             double sigmaPerVoxel, openvdb::util::NullInterrupter* interrupter,
                             std::vector<Column>& columns) const
{
    const Intersector master(mask);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, columns.size(), 64),
                      [&](const tbb::blocked_range<size_t>& range) {
                          Intersector inter(master);
                          DensityReader acc(density.tree(), padded);
                          for (size_t c = range.begin(); c != range.end(); ++c) {
                              if (interrupter && interrupter->wasInterrupted()) return;
                              const int i = int(c % size_t(mCount[0])),
                                        j = int(c / size_t(mCount[0]));
                              const Vec3d start = mU * (mOrigin.x() + i * mSpacing) +
                                                  mV * (mOrigin.y() + j * mSpacing) +
                                                  mW * mOrigin.z();
                              march(inter, acc, levelSet, start, length, sigmaPerVoxel, columns[c]);
                          }
                      });
}

void ShadowMap::pack(const std::vector<Column>& columns)
{
    size_t total = 0;
    for (const Column& c : columns) total += c.values.size();
    mData.reserve(total);
    mSpans.resize(columns.size());
    for (size_t c = 0; c < columns.size(); ++c) {
        const Column& col = columns[c];
        mSpans[c] = Span{col.first, int(col.values.size()), col.last, uint32_t(mData.size())};
        mData.insert(mData.end(), col.values.begin(), col.values.end());
    }
}

void ShadowMap::march(Intersector& inter, DensityReader& acc, bool levelSet, const Vec3d& start,
                      double length, double sigmaPerVoxel, Column& column) const
{
    if (!inter.setWorldRay(VdbRay(start, mW, 0.0, length))) return;
    const Medium1D ray{inter.getIndexPos(0.0), inter.getIndexPos(1.0) - inter.getIndexPos(0.0),
                       levelSet};
    // Index time per lattice step (the index ray has unit speed in voxels).
    const double h = inter.getWorldTime(1.0) > 0.0 ? mSpacing / inter.getWorldTime(1.0) : mSpacing;
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    int k = -1; // the last lattice index stored
    auto push = [&] {
        column.values.push_back(float(std::exp(-tau)));
        ++k;
    };
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
std::vector<Shadow> buildShadows(const FloatGrid& density, const PaddedLeaves& padded,
                                 const openvdb::BoolGrid& mask, bool levelSet,
                                 const std::vector<Light>& lights, double sigmaPerVoxel,
                                 int shadowCacheVoxels, openvdb::util::NullInterrupter* interrupter)
{
    const double voxel = density.voxelSize()[0];
    std::vector<Shadow> shadows(lights.size());
    for (size_t l = 0; l < lights.size(); ++l) {
        if (interrupter && interrupter->wasInterrupted()) break;
        if (shadowCacheVoxels <= 0) break; // exact transmittance per sample: nothing to build
        if (lights[l].type == Light::Type::Directional)
            shadows[l].map = std::make_unique<ShadowMap>(
                density, padded, mask, levelSet, lights[l].direction, sigmaPerVoxel,
                voxel * std::max(1, shadowCacheVoxels), interrupter);
        else if (lights[l].type == Light::Type::Point)
            shadows[l].cache = pointLightCache(density, padded, mask, levelSet, lights[l],
                                               sigmaPerVoxel, shadowCacheVoxels, interrupter);
    }
    return shadows;
}

} // namespace volmorph::render
