#include "blend/SdfVelocity.h"

#include <volmorph/Voxelize.h>

#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

namespace volmorph::detail {
namespace {

/// One recorded field around a leaf: within the leaf read from its buffer and mask, beyond it
/// through an accessor (most of a gradient's reads stay in the leaf).
class Field {
public:
    Field(const openvdb::FloatTree& tree, const openvdb::Coord& origin)
        : mAccessor(tree), mLeaf(tree.probeConstLeaf(origin)), mOrigin(origin)
    {
        if (mLeaf) mValues = mLeaf->buffer().data();
    }

    /// The value at voxel n of the leaf (recorded there).
    float at(openvdb::Index n) const { return mValues[n]; }

    /// The value at ijk; false where nothing was recorded.
    bool probe(const openvdb::Coord& ijk, float& value) const
    {
        const openvdb::Coord l = ijk - mOrigin;
        if (mLeaf && unsigned(l.x()) < 8u && unsigned(l.y()) < 8u && unsigned(l.z()) < 8u) {
            const openvdb::Index n = openvdb::Index((l.x() << 6) | (l.y() << 3) | l.z());
            value = mValues[n];
            return mLeaf->getValueMask().isOn(n);
        }
        return mAccessor.probeValue(ijk, value);
    }

private:
    mutable openvdb::tree::ValueAccessor<const openvdb::FloatTree> mAccessor;
    const openvdb::FloatTree::LeafNodeType* mLeaf;
    const float* mValues = nullptr;
    openvdb::Coord mOrigin;
};

/// Where |grad phi| falls below this fraction of a distance's gradient, the normal is undefined.
constexpr float kMinGradient = 0.25f;

/// The derivative of the recorded field along `axis` at ijk (per index unit): central where both
/// neighbours were recorded, else one-sided (second order when two voxels on that side were, first
/// order when one was). False when neither neighbour was.
bool derivative(const Field& a, const openvdb::Coord& ijk, float centre, int axis, float& out)
{
    openvdb::Coord step(0);
    step[axis] = 1;
    float p1 = 0.0f, m1 = 0.0f, p2 = 0.0f, m2 = 0.0f;
    const bool hasP1 = a.probe(ijk + step, p1), hasM1 = a.probe(ijk - step, m1);
    if (hasP1 && hasM1) {
        out = 0.5f * (p1 - m1);
    } else if (hasP1) {
        out =
            a.probe(ijk + step + step, p2) ? 0.5f * (-3.0f * centre + 4.0f * p1 - p2) : p1 - centre;
    } else if (hasM1) {
        out =
            a.probe(ijk - step - step, m2) ? 0.5f * (3.0f * centre - 4.0f * m1 + m2) : centre - m1;
    } else {
        return false;
    }
    return true;
}

bool gradient(const Field& a, const openvdb::Coord& ijk, float centre, Vec3f& out)
{
    return derivative(a, ijk, centre, 0, out[0]) && derivative(a, ijk, centre, 1, out[1]) &&
           derivative(a, ijk, centre, 2, out[2]);
}

} // namespace

void SdfVelocity::leaf(const openvdb::FloatTree& source, const openvdb::FloatTree& target,
                       const openvdb::util::NodeMask<3>& on, VectorLeaf& velocity,
                       VectorLeaf& correction) const
{
    const openvdb::Coord origin = velocity.origin();
    const Field a(source, origin), b(target, origin);
    // The shell near the surface; the rest of what was recorded is left to the extension.
    openvdb::util::NodeMask<3> shell;
    for (auto it = on.beginOn(); it; ++it) {
        if (std::abs((1.0f - mTau) * a.at(it.pos()) + mTau * b.at(it.pos())) < mShell)
            shell.setOn(it.pos());
        else
            velocity.setValueOff(it.pos());
    }
    if (shell.isOff()) return;
    Vec3f vs[512], vt[512];
    mBlend.count(mBlend.warpVelocity().fill(origin, shell, vs, vt));
    for (auto it = shell.beginOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const openvdb::Coord ijk = origin + VectorLeaf::offsetToLocalCoord(n);
        const float da = a.at(n), db = b.at(n);
        const float wa = (1.0f - mTau) * fogRamp(da, mRamp), wb = mTau * fogRamp(db, mRamp);
        const Vec3f warp = wa + wb > 0.0f ? (wa * vs[n] + wb * vt[n]) / (wa + wb)
                                          : (1.0f - mTau) * vs[n] + mTau * vt[n];
        Vec3f fix(0.0f), ga, gb;
        if (gradient(a, ijk, da, ga) && gradient(b, ijk, db, gb)) {
            const Vec3f normal = (1.0f - mTau) * ga + mTau * gb;
            const float length2 = normal.lengthSqr();
            const float floor = kMinGradient * std::max(ga.length(), gb.length());
            if (length2 > floor * floor) {
                const float rate =
                    mSlope * (db - da) - (1.0f - mTau) * ga.dot(vs[n]) - mTau * gb.dot(vt[n]);
                fix = ((-rate - warp.dot(normal)) / length2) * normal;
            }
        }
        velocity.setValueOn(n, (warp + fix) * mScale);
        correction.setValueOn(n, fix);
    }
}

void SdfVelocity::extrapolate(openvdb::Vec3STree& correction)
{
    const openvdb::MaskTree before(correction, false, openvdb::TopologyCopy());
    openvdb::tools::dilateActiveValues(correction, 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(correction);
    // Each new voxel reads only voxels of the layer before, which no thread writes.
    leaves.foreach ([&](VectorLeaf& leaf, size_t) {
        openvdb::util::NodeMask<3> added = leaf.getValueMask();
        if (const auto* old = before.probeConstLeaf(leaf.origin())) added -= old->getValueMask();
        if (added.isOff()) return;
        const openvdb::tree::ValueAccessor<const openvdb::MaskTree> known(before);
        const openvdb::tree::ValueAccessor<const openvdb::Vec3STree> values(correction);
        for (auto it = added.beginOn(); it; ++it) {
            const openvdb::Coord ijk = leaf.offsetToGlobalCoord(it.pos());
            Vec3f sum(0.0f);
            int count = 0;
            for (int dx = -1; dx <= 1; ++dx)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dz = -1; dz <= 1; ++dz) {
                        const openvdb::Coord q = ijk.offsetBy(dx, dy, dz);
                        if (!known.isValueOn(q)) continue;
                        sum += values.getValue(q);
                        ++count;
                    }
            leaf.setValueOnly(it.pos(), count > 0 ? sum / float(count) : Vec3f(0.0f));
        }
    });
}

openvdb::Vec3SGrid::Ptr SdfVelocity::make(const openvdb::FloatTree& source,
                                          const openvdb::FloatTree& target, double seconds,
                                          double voxelSize) const
{
    auto velocity = openvdb::Vec3SGrid::create(Vec3f(0.0f));
    velocity->tree().topologyUnion(source); // the target's was recorded at the same voxels
    openvdb::Vec3STree correction(velocity->tree(), Vec3f(0.0f), openvdb::TopologyCopy());
    {
        openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity->tree());
        leaves.foreach ([&](VectorLeaf& v, size_t) {
            const openvdb::util::NodeMask<3> recorded = v.getValueMask();
            VectorLeaf& fix = *correction.probeLeaf(v.origin());
            leaf(source, target, recorded, v, fix);
            fix.setValueMask(v.getValueMask());
        });
    }
    openvdb::tools::pruneInactive(velocity->tree());
    openvdb::tools::pruneInactive(correction);
    if (!(seconds > 0.0)) return velocity;
    const openvdb::MaskTree band(velocity->tree(), false, openvdb::TopologyCopy());
    const int reach = mBlend.extend(*velocity, seconds, voxelSize);
    for (int layer = 0; layer < reach; ++layer) extrapolate(correction);
    openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity->tree());
    leaves.foreach ([&](VectorLeaf& v, size_t) {
        openvdb::util::NodeMask<3> added = v.getValueMask();
        if (const auto* old = band.probeConstLeaf(v.origin())) added -= old->getValueMask();
        const VectorLeaf* fix = correction.probeConstLeaf(v.origin());
        if (!fix) return;
        for (auto it = added.beginOn(); it; ++it)
            v.setValueOnly(it.pos(), v.getValue(it.pos()) + fix->getValue(it.pos()) * mScale);
    });
    return velocity;
}

} // namespace volmorph::detail
