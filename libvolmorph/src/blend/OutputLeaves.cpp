#include "blend/OutputLeaves.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/MemoryLimit.h>

#include <algorithm>
#include <cstdio>

namespace volmorph::detail {

OutputLeaves::OutputLeaves(double t, uint64_t limitBytes, uint64_t residentBytes,
                           uint64_t bytesPerLeaf, Vec3f background)
    : mT(t), mLimit(limitBytes), mResident(residentBytes), mBytesPerLeaf(bytesPerLeaf),
      mMaxLeaves(size_t(std::max<uint64_t>(
          1, (limitBytes > residentBytes ? limitBytes - residentBytes : 0) / bytesPerLeaf))),
      mBackground(background)
{
}

OutputLeaves::~OutputLeaves() = default;

std::pair<std::unique_ptr<OutputLeaves::ValueLeaf>, std::unique_ptr<OutputLeaves::ColorLeaf>>
OutputLeaves::make(const openvdb::Coord& origin, float value) const
{
    return {std::make_unique<ValueLeaf>(origin, value, false),
            std::make_unique<ColorLeaf>(origin, mBackground, false)};
}

void OutputLeaves::keep(std::unique_ptr<ValueLeaf> value, std::unique_ptr<ColorLeaf> color,
                        ExtraLeaves extras)
{
    std::lock_guard<std::mutex> lock(mMutex);
    if (mLeaves.size() >= mMaxLeaves) {
        char text[400];
        std::snprintf(text, sizeof text,
                      "the in-between at t = %.4f needs more than the memory limit of %.1f GiB "
                      "(%.1f GiB in use before it, and over %zu blocks of 8^3 voxels); use a "
                      "larger voxel size, check the feature pairs' scales, or raise the memory "
                      "limit",
                      mT, double(mLimit) / double(1ull << 30),
                      double(mResident) / double(1ull << 30), mMaxLeaves);
        throw MemoryLimitExceeded(SourceLocation{"morph"}, text,
                                  mResident + (mMaxLeaves + 1) * mBytesPerLeaf, mLimit);
    }
    mLeaves.push_back(Kept{std::move(value), std::move(color), std::move(extras)});
}

void OutputLeaves::insideTile(const openvdb::Coord& origin)
{
    std::lock_guard<std::mutex> lock(mMutex);
    mInside.push_back(origin);
}

void OutputLeaves::uniformTile(const openvdb::Coord& origin, float value, const Vec3f& color)
{
    std::lock_guard<std::mutex> lock(mMutex);
    mUniform.push_back(Uniform{origin, value, color});
}

void OutputLeaves::moveInto(openvdb::FloatTree& values, openvdb::Vec3STree& colors,
                            float insideValue, const ExtraTrees& extras)
{
    for (Kept& k : mLeaves) {
        values.addLeaf(k.value.release());
        colors.addLeaf(k.color.release());
        for (size_t i = 0; i < k.extras.floats.size(); ++i)
            extras.floats[i]->addLeaf(k.extras.floats[i].release());
        for (size_t i = 0; i < k.extras.vectors.size(); ++i)
            extras.vectors[i]->addLeaf(k.extras.vectors[i].release());
        if (extras.velocity && k.extras.velocity)
            extras.velocity->addLeaf(k.extras.velocity.release());
        for (int side = 0; side < 2; ++side)
            if (extras.distances[side] && k.extras.distances[side])
                extras.distances[side]->addLeaf(k.extras.distances[side].release());
    }
    mLeaves.clear();
    for (const openvdb::Coord& origin : mInside) values.addTile(1, origin, insideValue, false);
    for (const Uniform& u : mUniform) {
        values.addTile(1, u.origin, u.value, true);
        colors.addTile(1, u.origin, u.color, true);
    }
    mUniform.clear();
}

} // namespace volmorph::detail
