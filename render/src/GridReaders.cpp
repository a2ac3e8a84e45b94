#include "GridReaders.h"

#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Morphology.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace volmorph::render {

openvdb::BoolGrid::Ptr rayMask(const openvdb::FloatGrid& density, bool levelSet)
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

PaddedLeaves::PaddedLeaves(const openvdb::FloatTree& tree)
{
    std::vector<const Leaf*> leaves;
    leaves.reserve(tree.leafCount());
    for (auto it = tree.cbeginLeaf(); it; ++it) {
        const float* d = it->buffer().data();
        if (!std::all_of(d + 1, d + Leaf::SIZE, [d](float v) { return v == d[0]; }))
            leaves.push_back(&*it);
    }
    mValues.resize(leaves.size() * kSize);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                          openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(tree);
                          for (size_t i = r.begin(); i != r.end(); ++i) {
                              const Leaf& leaf = *leaves[i];
                              const float* d = leaf.buffer().data();
                              float* out = &mValues[i * kSize];
                              for (int x = 0; x < kSide; ++x)
                                  for (int y = 0; y < kSide; ++y)
                                      for (int z = 0; z < kSide; ++z)
                                          out[(x * kSide + y) * kSide + z] =
                                              x < 8 && y < 8 && z < 8
                                                  ? d[(x << 6) | (y << 3) | z]
                                                  : acc.getValue(leaf.origin().offsetBy(x, y, z));
                          }
                      });
    mIndex.reserve(leaves.size());
    for (size_t i = 0; i < leaves.size(); ++i) mIndex.emplace(leaves[i], &mValues[i * kSize]);
}

} // namespace volmorph::render
