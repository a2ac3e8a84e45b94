// The output leaves of one frame, collected from the warp's threads, under the memory guard: a
// warp that blows the shape up (a pair scaling by 100, say) would otherwise fill the machine's
// memory leaf by leaf.
#pragma once

#include <volmorph/core/Math.h>

#include <openvdb/openvdb.h>

#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace volmorph::detail {

/// One output leaf of each extra grid (ExtraGrids.h), in its order.
struct ExtraLeaves {
    std::vector<std::unique_ptr<openvdb::FloatTree::LeafNodeType>> floats;
    std::vector<std::unique_ptr<openvdb::Vec3STree::LeafNodeType>> vectors;
    /// The velocity's leaf (VelocityBlend.h), when the frame has one.
    std::unique_ptr<openvdb::Vec3STree::LeafNodeType> velocity;
    /// sdf mode with velocity: each side's distance at the voxels' warped points (SdfVelocity.h).
    std::unique_ptr<openvdb::FloatTree::LeafNodeType> distances[2];
};

/// The trees each kind of ExtraLeaves goes into (null: none kept).
struct ExtraTrees {
    std::vector<openvdb::FloatTree*> floats; ///< in ExtraLeaves::floats' order
    std::vector<openvdb::Vec3STree*> vectors;
    openvdb::Vec3STree* velocity = nullptr;
    openvdb::FloatTree* distances[2] = {nullptr, nullptr};
};

class OutputLeaves {
public:
    using ValueLeaf = openvdb::FloatTree::LeafNodeType;
    using ColorLeaf = openvdb::Vec3STree::LeafNodeType;

    /// t: the frame's, for the message; at most `(limitBytes - residentBytes) / bytesPerLeaf`
    /// leaves are kept (`residentBytes`: what the process holds before the frame); colour leaves
    /// start at `background`.
    OutputLeaves(double t, uint64_t limitBytes, uint64_t residentBytes, uint64_t bytesPerLeaf,
                 Vec3f background);
    ~OutputLeaves();
    OutputLeaves(const OutputLeaves&) = delete;
    OutputLeaves& operator=(const OutputLeaves&) = delete;

    /// A value leaf (background `value`, inactive) and a colour leaf at `origin`.
    std::pair<std::unique_ptr<ValueLeaf>, std::unique_ptr<ColorLeaf>>
    make(const openvdb::Coord& origin, float value) const;

    /// Keeps them all; throws UserError past the memory limit.
    void keep(std::unique_ptr<ValueLeaf> value, std::unique_ptr<ColorLeaf> color,
              ExtraLeaves extras = {});
    /// A leaf-sized tile inside the object (sdf mode).
    void insideTile(const openvdb::Coord& origin);
    /// A leaf-sized block of one value and colour (density mode's uniform interiors): active
    /// tiles of both trees.
    void uniformTile(const openvdb::Coord& origin, float value, const Vec3f& color);

    size_t size() const { return mLeaves.size(); }
    const Vec3f& background() const { return mBackground; }

    /// Moves the leaves into the trees (the extras' into `extras`); inside tiles (leaf-sized) of
    /// the value tree get `insideValue`.
    void moveInto(openvdb::FloatTree& values, openvdb::Vec3STree& colors, float insideValue,
                  const ExtraTrees& extras = {});

private:
    double mT;
    uint64_t mLimit, mResident, mBytesPerLeaf;
    size_t mMaxLeaves;
    Vec3f mBackground;
    std::mutex mMutex;
    struct Kept {
        std::unique_ptr<ValueLeaf> value;
        std::unique_ptr<ColorLeaf> color;
        ExtraLeaves extras;
    };
    std::vector<Kept> mLeaves;
    std::vector<openvdb::Coord> mInside;
    struct Uniform {
        openvdb::Coord origin;
        float value;
        Vec3f color;
    };
    std::vector<Uniform> mUniform;
};

} // namespace volmorph::detail
