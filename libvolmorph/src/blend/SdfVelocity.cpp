#include "blend/SdfVelocity.h"

#include "blend/VelocityReach.h"

#include <volmorph/Voxelize.h>

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <memory>

namespace volmorph::detail {
namespace {

/// One recorded field around a leaf, dense: the leaf and two layers of each of its six face
/// neighbours (all that a second-order one-sided difference along an axis reaches), and which of
/// those voxels were recorded (NaN where not). Copied once per leaf from the leaves' buffers: a
/// gradient's twelve reads are then array reads, not tree probes.
class Field {
public:
    static constexpr int kPad = 2, kSide = 8 + 2 * kPad;

    Field(const openvdb::FloatTree& tree, const openvdb::Coord& origin)
    {
        std::fill(std::begin(mValues), std::end(mValues), kUnknown);
        copy(tree.probeConstLeaf(origin), openvdb::Coord(0), 0, 8);
        for (int axis = 0; axis < 3; ++axis)
            for (const int side : {-1, 1}) {
                openvdb::Coord step(0);
                step[axis] = side * 8;
                // The two layers of the neighbour next to this leaf: its local 0..1 or 6..7.
                const int first = side > 0 ? 0 : 6;
                copy(tree.probeConstLeaf(origin + step), step, axis, first);
            }
    }

    /// The value at voxel n of the leaf (recorded there).
    float at(openvdb::Index n) const { return mValues[index(n)]; }

    /// The value at index i of the dense block (index()); false where nothing was recorded.
    bool probe(int i, float& value) const
    {
        value = mValues[i];
        return !std::isnan(value);
    }

    /// The dense block's index of the leaf's local (x, y, z), each in -2..9.
    static int index(int x, int y, int z)
    {
        return ((x + kPad) * kSide + (y + kPad)) * kSide + (z + kPad);
    }
    static int index(openvdb::Index n) { return index(int(n >> 6), int((n >> 3) & 7), int(n & 7)); }

private:
    /// Copies `leaf` (at `offset` from this leaf, in voxels) into the dense block: all of it when
    /// `first` is 0 and 8 voxels are wanted, else the two layers from `first` along `axis`.
    void copy(const openvdb::FloatTree::LeafNodeType* leaf, const openvdb::Coord& offset, int axis,
              int first)
    {
        if (!leaf) return;
        const float* values = leaf->buffer().data();
        const auto& mask = leaf->getValueMask();
        int lo[3] = {0, 0, 0}, hi[3] = {8, 8, 8};
        if (offset != openvdb::Coord(0)) {
            lo[axis] = first;
            hi[axis] = first + kPad;
        }
        for (int x = lo[0]; x < hi[0]; ++x)
            for (int y = lo[1]; y < hi[1]; ++y)
                for (int z = lo[2]; z < hi[2]; ++z) {
                    const openvdb::Index n = openvdb::Index((x << 6) | (y << 3) | z);
                    const int i = index(x + offset.x(), y + offset.y(), z + offset.z());
                    mValues[i] = mask.isOn(n) ? values[n] : kUnknown;
                }
    }

    static constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN(); ///< not recorded
    float mValues[kSide * kSide * kSide];
};

/// Where |grad phi| falls below this fraction of a distance's gradient, the normal is undefined.
constexpr float kMinGradient = 0.25f;

/// The derivative of the recorded field along an axis at the dense block's index i, `step` apart
/// along the axis (per index unit): central where both neighbours were recorded, else one-sided
/// (second order when two voxels on that side were, first order when one was). False when
/// neither neighbour was.
inline bool derivative(const Field& a, int i, int step, float centre, float& out)
{
    float p1 = 0.0f, m1 = 0.0f, p2 = 0.0f, m2 = 0.0f;
    const bool hasP1 = a.probe(i + step, p1), hasM1 = a.probe(i - step, m1);
    if (hasP1 && hasM1) {
        out = 0.5f * (p1 - m1);
    } else if (hasP1) {
        out = a.probe(i + 2 * step, p2) ? 0.5f * (-3.0f * centre + 4.0f * p1 - p2) : p1 - centre;
    } else if (hasM1) {
        out = a.probe(i - 2 * step, m2) ? 0.5f * (3.0f * centre - 4.0f * m1 + m2) : centre - m1;
    } else {
        return false;
    }
    return true;
}

/// The gradient at the leaf's voxel n.
inline bool gradient(const Field& a, openvdb::Index n, float centre, Vec3f& out)
{
    const int i = Field::index(n);
    return derivative(a, i, Field::kSide * Field::kSide, centre, out[0]) &&
           derivative(a, i, Field::kSide, centre, out[1]) && derivative(a, i, 1, centre, out[2]);
}

} // namespace

openvdb::MaskTree SdfVelocity::shell(const openvdb::FloatTree& source,
                                     const openvdb::FloatTree& target) const
{
    openvdb::MaskTree out(source, false, openvdb::TopologyCopy()); // the target's: the same
    openvdb::tree::LeafManager<openvdb::MaskTree> leaves(out);
    leaves.foreach ([&](openvdb::MaskTree::LeafNodeType& leaf, size_t) {
        const auto* a = source.probeConstLeaf(leaf.origin());
        const auto* b = target.probeConstLeaf(leaf.origin());
        openvdb::util::NodeMask<3> near;
        if (a && b) // recorded together: never one without the other
            for (auto it = a->cbeginValueOn(); it; ++it) {
                const float tau = mTime.at(it.getCoord()).tau;
                const float phi = (1.0f - tau) * *it + tau * b->getValue(it.pos());
                if (std::abs(phi) < mShell) near.setOn(it.pos());
            }
        leaf.setValueMask(near);
    });
    openvdb::tools::pruneInactive(out);
    return out;
}

void SdfVelocity::leaf(const openvdb::FloatTree& source, const openvdb::FloatTree& target,
                       VectorLeaf& velocity, VectorLeaf* correction) const
{
    const openvdb::Coord origin = velocity.origin();
    const openvdb::util::NodeMask<3> shell = velocity.getValueMask();
    const Field a(source, origin), b(target, origin);
    Vec3f vs[512], vt[512];
    mBlend.count(mBlend.warpVelocity().fill(origin, shell, vs, vt));
    for (auto it = shell.beginOn(); it; ++it) {
        const openvdb::Index n = it.pos();
        const float da = a.at(n), db = b.at(n);
        const VoxelTau time = mTime.at(origin + VectorLeaf::offsetToLocalCoord(n));
        const float tau = time.tau;
        const float wa = (1.0f - tau) * fogRamp(da, mRamp), wb = tau * fogRamp(db, mRamp);
        const Vec3f warp = wa + wb > 0.0f ? (wa * vs[n] + wb * vt[n]) / (wa + wb)
                                          : (1.0f - tau) * vs[n] + tau * vt[n];
        Vec3f fix(0.0f), ga, gb;
        if (gradient(a, n, da, ga) && gradient(b, n, db, gb)) {
            // grad phi, with the chain rule through tau's own gradient under a timing.
            const Vec3f normal = (1.0f - tau) * ga + tau * gb + (db - da) * time.gradient;
            const float length2 = normal.lengthSqr();
            const float floor = kMinGradient * std::max(ga.length(), gb.length());
            if (length2 > floor * floor) {
                const float rate =
                    time.dt * (db - da) - (1.0f - tau) * ga.dot(vs[n]) - tau * gb.dot(vt[n]);
                fix = ((-rate - warp.dot(normal)) / length2) * normal;
            }
        }
        velocity.setValueOnly(n, (warp + fix) * mScale);
        if (correction) correction->setValueOnly(n, fix); // its mask: the velocity's (a copy)
    }
}

openvdb::Vec3SGrid::Ptr SdfVelocity::make(const openvdb::FloatTree& source,
                                          const openvdb::FloatTree& target, double seconds,
                                          double voxelSize) const
{
    // Leaves are made only where the shell is: the rest of what was recorded is left to the
    // extension (a Vec3 leaf is 6 KB; the recorded leaves are some twice the shell's).
    const openvdb::MaskTree near = shell(source, target);
    auto velocity = openvdb::Vec3SGrid::create(Vec3f(0.0f));
    velocity->tree().topologyUnion(near);
    const bool reach = seconds > 0.0;
    std::unique_ptr<openvdb::Vec3STree> correction;
    if (reach)
        correction = std::make_unique<openvdb::Vec3STree>(velocity->tree(), Vec3f(0.0f),
                                                          openvdb::TopologyCopy());
    {
        openvdb::tree::LeafManager<openvdb::Vec3STree> leaves(velocity->tree());
        leaves.foreach ([&](VectorLeaf& v, size_t) {
            leaf(source, target, v, reach ? correction->probeLeaf(v.origin()) : nullptr);
        });
    }
    if (!reach) return velocity;
    VelocityReach(mBlend, seconds, voxelSize).grow(*velocity, std::move(correction));
    return velocity;
}

} // namespace volmorph::detail
