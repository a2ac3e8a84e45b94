#include "blend/ExtendedDistance.h"

#include "blend/LeafApron.h"

#include <openvdb/math/Stencils.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tree/LeafManager.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <atomic>
#include <memory>
#include <stdexcept>
#include <utility>

namespace volmorph::detail {

using openvdb::Coord;
using openvdb::CoordBBox;

namespace {

int floorDiv(int v, int s)
{
    return v >= 0 ? v / s : -((-v + s - 1) / s);
}

openvdb::FloatGrid::Ptr lattice(float background, double spacing)
{
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(background);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(spacing));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return grid;
}

/// The point of the band's zero set nearest a point near it, p - phi grad phi (the band's index
/// space), for tools::sdfToExt, which copies it per thread. OpenVDB 10's FastSweeping calls it
/// with the lattice's index coordinates, not world ones (its extension grid keeps the identity
/// transform): `scale` takes them to the band's (the sphere test of ExtendedDistance fails
/// loudly should that change).
class FootPoint {
public:
    FootPoint(const openvdb::FloatGrid::ConstPtr& band, double scale)
        : mBand(band), mStencil(*band), mVoxel(band->voxelSize()[0]), mScale(scale)
    {
    }
    FootPoint(const FootPoint& o) : FootPoint(o.mBand, o.mScale) {}
    openvdb::Vec3s operator()(const openvdb::Vec3d& lattice) const
    {
        const openvdb::Vec3d p = lattice * mScale;
        bool near;
        return openvdb::Vec3s(project(p, near));
    }

    /// The projection of p (the band's index space) onto the zero set; `near` says whether it
    /// was made from well inside the band, where it holds. `shell` (the shell's tree, kShell
    /// voxels apart): from farther out, a first step along the shell's gradient.
    openvdb::Vec3d project(openvdb::Vec3d p, bool& near,
                           const openvdb::FloatTree* shell = nullptr) const
    {
        if (shell) {
            openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(*shell);
            p = step(acc, p, double(ExtendedDistance::kShell));
        }
        return onBand(p, near);
    }

    /// The same from a node of the shell (`acc` on it, `value` its value): the first step's
    /// gradient is the central differences of its neighbours.
    template <typename Accessor>
    openvdb::Vec3d projectNode(Accessor& acc, const openvdb::Coord& node, float value,
                               bool& near) const
    {
        constexpr double h = ExtendedDistance::kShell;
        openvdb::Vec3d g;
        for (int k = 0; k < 3; ++k) {
            openvdb::Coord e(0);
            e[k] = 1;
            g[k] = (acc.getValue(node + e) - acc.getValue(node - e)) / (2.0 * h * mVoxel);
        }
        const double length = g.length();
        const openvdb::Vec3d p = node.asVec3d() * h;
        return onBand(length > 0.0 ? p - g * (value / mVoxel / length) : p, near);
    }

private:
    /// The band's step from p, `near` when p lies well inside the band. The value and gradient
    /// are the trilinear cell's around p (math::BoxStencil): p lies within a voxel or two of the
    /// surface by now, so the gradient's first-order error moves the point sideways by a fraction
    /// of that, which changes a distance only to second order.
    openvdb::Vec3d onBand(const openvdb::Vec3d& p, bool& near) const
    {
        const openvdb::Vec3s q(p);
        mStencil.moveTo(q);
        const double phi = mStencil.interpolation(q) / mVoxel;
        const openvdb::Vec3d g(mStencil.gradient(q));
        near = std::abs(phi) < mBand->background() / mVoxel - 1.0;
        const double length = g.length();
        return near && length > 0.0 ? p - g * (phi / length) : p;
    }

    /// p - phi grad phi, from the grid behind `acc` with its lattice `spacing` voxels apart
    /// (trilinear phi and central differences).
    template <typename Accessor>
    openvdb::Vec3d step(Accessor& acc, const openvdb::Vec3d& p, double spacing) const
    {
        using openvdb::tools::BoxSampler;
        const openvdb::Vec3d q = p / spacing;
        const double phi = sample<BoxSampler>(acc, q) / mVoxel;
        openvdb::Vec3d g;
        for (int k = 0; k < 3; ++k) {
            openvdb::Vec3d e(0.0);
            e[k] = 1.0;
            g[k] = (sample<BoxSampler>(acc, q + e) - sample<BoxSampler>(acc, q - e)) /
                   (2.0 * spacing * mVoxel);
        }
        const double length = g.length();
        return length > 0.0 ? p - g * (phi / length) : p;
    }

    openvdb::FloatGrid::ConstPtr mBand;
    mutable openvdb::math::BoxStencil<openvdb::FloatGrid, false> mStencil; ///< one thread's
    double mVoxel, mScale;
};

} // namespace

CoordBBox ExtendedDistance::boxFor(const openvdb::FloatGrid& sourceBand,
                                   const openvdb::FloatGrid& targetBand, size_t pairCount)
{
    CoordBBox box = sourceBand.evalActiveVoxelBoundingBox();
    box.expand(targetBand.evalActiveVoxelBoundingBox());
    if (box.empty()) return box;
    const Coord dim = box.dim();
    const int margin = pairCount == 0 ? 8 : std::max(8, std::max({dim.x(), dim.y(), dim.z()}) / 8);
    box.expand(margin);
    return box;
}

ExtendedDistance::ExtendedDistance(openvdb::FloatGrid::ConstPtr band, const CoordBBox& box,
                                   Interrupter& stop)
    : mBand(std::move(band))
{
    mVoxel = float(mBand->voxelSize()[0]);
    if (box.empty()) return;
    Interrupter* interrupter = &stop;
    const auto check = [interrupter] { throwIfInterrupted(interrupter); };
    // The shell: the seeds' band dilated by kShellCells lattice cells, every way.
    const openvdb::FloatGrid::Ptr shell =
        openvdb::tools::dilateSdf(*shellSeeds(), kShellCells, openvdb::tools::NN_FACE_EDGE_VERTEX);
    if (!shell)
        throw std::runtime_error(
            "sdf blend: fast sweeping could not extend a signed distance field");
    // Beyond the shell, +/- a value no read takes for a distance (see Reader::extended).
    openvdb::tools::signedFloodFill(shell->tree());
    openvdb::tools::changeLevelSetBackground(shell->tree(), 1.0e6f * mVoxel);
    check();
    toSurfacePoints(shell->tree(), interrupter);
    check();
    const CoordBBox far(
        Coord(floorDiv(box.min().x(), kFarSpacing), floorDiv(box.min().y(), kFarSpacing),
              floorDiv(box.min().z(), kFarSpacing)),
        Coord(floorDiv(box.max().x(), kFarSpacing) + 1, floorDiv(box.max().y(), kFarSpacing) + 1,
              floorDiv(box.max().z(), kFarSpacing) + 1));
    const openvdb::FloatGrid::Ptr seeds = farSeeds(far, shell->tree());
    check();
    openvdb::BoolGrid mask(false);
    mask.setTransform(seeds->transform().copy());
    mask.sparseFill(far, true, true);
    const openvdb::FloatGrid::Ptr wide =
        openvdb::tools::maskSdf(*seeds, mask, /*ignoreActiveTiles*/ false, /*nIter*/ 1);
    if (!wide)
        throw std::runtime_error(
            "sdf blend: fast sweeping could not extend a signed distance field");
    // First-order sweeping strays by a few voxels a hundred voxels out on so coarse a lattice, so
    // the distances are taken from the surface's points carried out along the characteristics
    // instead (tools::sdfToExt): each point of the lattice's zero crossing projected onto the
    // band's zero set, p - phi grad phi. A carried point is smeared sideways along the surface,
    // which changes |x - point| only to second order.
    check();
    const FootPoint foot(mBand, kFarSpacing);
    const openvdb::Vec3SGrid::Ptr feet =
        openvdb::tools::sdfToExt(*wide, foot, openvdb::Vec3s(kNoFoot), 0.0f);
    check();
    makeDense(*wide, *feet, shell->tree(), far);
    for (int pass = 0; pass < kSharePasses; ++pass) shareFeet();
    check();
    makeBlocks(shell->tree());
    measureErrors();
}

openvdb::FloatGrid::Ptr ExtendedDistance::shellSeeds() const
{
    const float background = mBand->background();
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    mBand->tree().getNodes(leaves);
    tbb::enumerable_thread_specific<openvdb::FloatTree> parts(background);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, leaves.size()), [&](const tbb::blocked_range<size_t>& r) {
            openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(parts.local());
            for (size_t i = r.begin(); i != r.end(); ++i)
                for (auto it = leaves[i]->cbeginValueOn(); it; ++it) {
                    const Coord c = it.getCoord();
                    if (((c.x() | c.y() | c.z()) & (kShell - 1)) == 0)
                        acc.setValueOn(Coord(c.x() / kShell, c.y() / kShell, c.z() / kShell), *it);
                }
        });
    openvdb::FloatGrid::Ptr seeds = lattice(background, kShell * double(mVoxel));
    for (auto& part : parts) seeds->tree().merge(part, openvdb::MERGE_ACTIVE_STATES);
    openvdb::tools::signedFloodFill(seeds->tree());
    return seeds;
}

void ExtendedDistance::toSurfacePoints(openvdb::FloatTree& shell, Interrupter* interrupter) const
{
    // Each lattice point steps along the swept field's gradient to near the surface, then onto
    // the band's zero set; its distance to that point replaces the swept one (first order,
    // 0.5 to 1 voxel off 30 voxels out). The step's direction is as good as the swept
    // gradient, and a point a little off sideways changes the distance only to second order.
    const FootPoint prototype(mBand, 1.0);
    openvdb::Vec3STree feet(shell, openvdb::Vec3s(kNoFoot), openvdb::TopologyCopy());
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(feet, 1);
    std::atomic<bool> stopped{false};
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, size_t i) {
        if (stopped || (interrupter && (i & 63) == 0 && interrupter->wasInterrupted())) {
            stopped = true;
            return;
        }
        const FootPoint surface(prototype); // its own accessor
        openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(shell);
        const auto& values = *shell.probeConstLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            bool near = false;
            const openvdb::Vec3d foot =
                surface.projectNode(acc, it.getCoord(), values.getValue(it.pos()), near);
            it.setValue(near ? openvdb::Vec3s(foot) : openvdb::Vec3s(kNoFoot));
        }
    });
    if (stopped) throw Interrupted();
    for (int pass = 0; pass < kShellSharePasses; ++pass) shareShellFeet(leaves);
    openvdb::tree::LeafManager<openvdb::FloatTree> values(shell);
    values.foreach ([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
        const auto& own = *feet.probeConstLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const openvdb::Vec3s& foot = own.getValue(it.pos());
            if (foot.x() == kNoFoot) continue;
            const openvdb::Vec3d p = it.getCoord().asVec3d() * double(kShell);
            it.setValue(std::copysign(float((p - openvdb::Vec3d(foot)).length()) * mVoxel, *it));
        }
    });
}

void ExtendedDistance::shareShellFeet(openvdb::tree::LeafManager<openvdb::Vec3STree>& leaves) const
{
    // As shareFeet does on the far lattice: a shell point whose own surface point is not its
    // nearest (across the shell's medial axes, inside a thin part or between two) takes the
    // nearest of its neighbours'. Each leaf first copies its neighbours' points next to it into
    // a dense block (LeafApron.h: one tree lookup per neighbour leaf, not per point).
    const openvdb::Vec3STree& feet = leaves.tree();
    leaves.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, size_t i) {
        openvdb::tree::ValueAccessor<const openvdb::Vec3STree, false> acc(feet);
        std::vector<openvdb::Vec3s> near(apron::kCount, openvdb::Vec3s(kNoFoot));
        const openvdb::Vec3STree::LeafNodeType* from = nullptr;
        apron::gather(
            leaf.origin(),
            [&](const Coord& origin) { return (from = acc.probeConstLeaf(origin)) != nullptr; },
            [&](openvdb::Index n, int d) { near[size_t(d)] = from->getValue(n); });
        openvdb::Vec3s* out = leaves.getBuffer(i, 1).data();
        for (auto it = leaf.cbeginValueOn(); it; ++it) {
            const openvdb::Vec3s p(it.getCoord().asVec3s() * float(kShell));
            const int centre = apron::index(it.pos());
            float best = std::numeric_limits<float>::max();
            openvdb::Vec3s foot(kNoFoot);
            for (const int d : apron::neighbours()) {
                const openvdb::Vec3s& f = near[size_t(centre + d)];
                const float e = (p - f).lengthSqr(); // huge where f is kNoFoot
                if (e < best) best = e, foot = f;
            }
            out[it.pos()] = foot;
        }
    });
    leaves.swapLeafBuffer(1);
}

void ExtendedDistance::makeBlocks(const openvdb::FloatTree& shell)
{
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    shell.getNodes(leaves);
    constexpr size_t n = kApron * kApron * kApron;
    mBlocks.resize(leaves.size() * n);
    mBlockIndex.reserve(leaves.size());
    for (size_t i = 0; i < leaves.size(); ++i) {
        const Coord o = leaves[i]->origin();
        mBlockIndex.emplace(Coord(o.x() >> 3, o.y() >> 3, o.z() >> 3), uint32_t(i));
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size()),
                      [&](const tbb::blocked_range<size_t>& r) {
                          openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> acc(shell);
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              const Coord o = leaves[i]->origin();
                              float* v = mBlocks.data() + i * n;
                              for (int x = 0; x < kApron; ++x)
                                  for (int y = 0; y < kApron; ++y)
                                      for (int z = 0; z < kApron; ++z)
                                          *v++ = acc.getValue(o.offsetBy(x, y, z));
                          }
                      });
}

openvdb::FloatGrid::Ptr ExtendedDistance::farSeeds(const CoordBBox& far,
                                                   const openvdb::FloatTree& shellTree) const
{
    const float background = mBand->background();
    const float trusted = (kShell * kShellCells - 4.0f) * mVoxel; // well inside the shell
    constexpr int kRatio = kFarSpacing / kShell;
    // Lattice values, in parallel over slabs of x one leaf thick; each slab fills its own tree,
    // and the slabs' leaves are disjoint, so merging moves nodes.
    const int x0 = far.min().x() & ~7, slabCount = (far.max().x() - x0) / 8 + 1;
    std::vector<openvdb::FloatTree::Ptr> slabs(static_cast<size_t>(slabCount));
    tbb::parallel_for(tbb::blocked_range<int>(0, slabCount), [&](const tbb::blocked_range<int>& r) {
        auto fine = mBand->getConstAccessor();
        openvdb::tree::ValueAccessor<const openvdb::FloatTree, false> shell(shellTree);
        for (int i = r.begin(); i != r.end(); ++i) {
            auto tree = std::make_shared<openvdb::FloatTree>(background);
            openvdb::tree::ValueAccessor<openvdb::FloatTree> acc(*tree);
            for (int x = std::max(x0 + 8 * i, far.min().x());
                 x <= std::min(x0 + 8 * i + 7, far.max().x()); ++x)
                for (int y = far.min().y(); y <= far.max().y(); ++y)
                    for (int z = far.min().z(); z <= far.max().z(); ++z) {
                        float value;
                        if (shell.probeValue(Coord(x * kRatio, y * kRatio, z * kRatio), value) &&
                            std::abs(value) < trusted)
                            acc.setValueOn(Coord(x, y, z), value);
                        else if (fine.getValue(Coord(x * kFarSpacing, y * kFarSpacing,
                                                     z * kFarSpacing)) < 0.0f)
                            acc.setValueOff(Coord(x, y, z), -background);
                    }
            slabs[size_t(i)] = tree;
        }
    });
    openvdb::FloatGrid::Ptr seeds = lattice(background, kFarSpacing * double(mVoxel));
    for (const auto& slab : slabs) seeds->tree().merge(*slab, openvdb::MERGE_NODES);
    openvdb::tools::pruneLevelSet(seeds->tree());
    return seeds;
}

void ExtendedDistance::makeDense(const openvdb::FloatGrid& wide, const openvdb::Vec3SGrid& feet,
                                 const openvdb::FloatTree& shell, const CoordBBox& far)
{
    DenseField& d = mFarField;
    d.origin = far.min();
    d.dim = far.dim();
    d.values.resize(size_t(d.dim.x()) * d.dim.y() * d.dim.z());
    d.feet.assign(d.values.size(), openvdb::Vec3s(kNoFoot));
    tbb::parallel_for(tbb::blocked_range<int>(0, d.dim.x()), [&](const tbb::blocked_range<int>& r) {
        auto acc = wide.getConstAccessor();
        auto footAcc = feet.getConstAccessor();
        const FootPoint surface(mBand, 1.0); // this thread's
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < d.dim.y(); ++y)
                for (int z = 0; z < d.dim.z(); ++z) {
                    const Coord q = d.origin.offsetBy(x, y, z);
                    float value = acc.getValue(q);
                    const openvdb::Vec3s f = footAcc.getValue(q);
                    // The carried point, averaged between neighbours by the sweep, lies a little
                    // off the surface: back onto it. Where it does not lie near it (around a medial
                    // point, where neighbours' points come from every side) the sweep's own
                    // value stays.
                    bool near = false;
                    const openvdb::Vec3d onSurface =
                        f.x() != kNoFoot ? surface.project(openvdb::Vec3d(f), near, &shell)
                                         : openvdb::Vec3d(0.0);
                    const size_t i = d.index(x, y, z);
                    if (near) {
                        const openvdb::Vec3d p(q.asVec3d() * double(kFarSpacing));
                        value = std::copysign(float((p - onSurface).length()) * mVoxel, value);
                        d.feet[i] = openvdb::Vec3s(onSurface);
                    }
                    d.values[i] = value;
                }
    });
}

void ExtendedDistance::shareFeet()
{
    // A carried point is a point of the surface, but not always the nearest: where the sweep's
    // characteristics cross (a medial axis, outside between the knot's loops or inside the bunny's
    // body) a lattice point keeps one side's point while the other side's is nearer, 6 to 14
    // voxels nearer 60 to 100 voxels out at 250 across, and points around a medial point have
    // none. Every surface point a neighbour holds bounds the distance from above too, so each
    // pass takes the nearest of them (closest-point propagation, as jump flooding does): never
    // under the distance, and exact once a point of the lattice near it holds the right one.
    DenseField& d = mFarField;
    std::vector<float> values(d.values.size());
    std::vector<openvdb::Vec3s> feet(d.feet.size());
    tbb::parallel_for(tbb::blocked_range<int>(0, d.dim.x()), [&](const tbb::blocked_range<int>& r) {
        for (int x = r.begin(); x != r.end(); ++x)
            for (int y = 0; y < d.dim.y(); ++y)
                for (int z = 0; z < d.dim.z(); ++z) {
                    const size_t i = d.index(x, y, z);
                    const openvdb::Vec3d p(d.origin.offsetBy(x, y, z).asVec3d() * kFarSpacing);
                    double best = std::numeric_limits<double>::max();
                    openvdb::Vec3s foot(kNoFoot);
                    for (int a = std::max(x - 1, 0); a <= std::min(x + 1, d.dim.x() - 1); ++a)
                        for (int b = std::max(y - 1, 0); b <= std::min(y + 1, d.dim.y() - 1); ++b)
                            for (int c = std::max(z - 1, 0); c <= std::min(z + 1, d.dim.z() - 1);
                                 ++c) {
                                const openvdb::Vec3s& f = d.feet[d.index(a, b, c)];
                                if (f.x() == kNoFoot) continue;
                                const double e = (p - openvdb::Vec3d(f)).lengthSqr();
                                if (e < best) best = e, foot = f;
                            }
                    feet[i] = foot;
                    values[i] = foot.x() == kNoFoot
                                    ? d.values[i]
                                    : std::copysign(float(std::sqrt(best)) * mVoxel, d.values[i]);
                }
    });
    d.values = std::move(values);
    d.feet = std::move(feet);
}

void ExtendedDistance::measureErrors()
{
    // How far the extended field strays from the band where both are defined (voxels): over the
    // whole band, so that a point whose extended value is beyond kFar + that needs no band read;
    // and where the extended field is used (|band| >= kNear), which bounds how much the field can
    // change beyond a distance's 1 per voxel.
    std::vector<const openvdb::FloatTree::LeafNodeType*> leaves;
    mBand->tree().getNodes(leaves);
    using Errors = std::pair<float, float>;
    const Errors errors = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, leaves.size()), Errors(0.0f, 0.0f),
        [&](const tbb::blocked_range<size_t>& r, Errors worst) {
            Reader<openvdb::tools::BoxSampler> read(*this);
            for (size_t i = r.begin(); i != r.end(); ++i)
                for (auto it = leaves[i]->cbeginValueOn(); it; ++it) {
                    const float e = std::abs(read.extended(it.getCoord().asVec3d()) - *it);
                    worst.first = std::max(worst.first, e);
                    if (std::abs(*it) >= kNear * mVoxel) worst.second = std::max(worst.second, e);
                }
            return worst;
        },
        [](Errors a, Errors b) {
            return Errors(std::max(a.first, b.first), std::max(a.second, b.second));
        });
    mExtendedError = errors.first / mVoxel;
    mTransitionError = errors.second / mVoxel;
}

} // namespace volmorph::detail
