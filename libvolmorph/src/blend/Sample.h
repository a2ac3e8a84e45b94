// The blend's one read of a grid at a warped point: OpenVDB's sampler, with a faster path for
// trilinear reads that gives the same bits.
#pragma once

#include <openvdb/Types.h>
#include <openvdb/tools/Interpolation.h>

#include <type_traits>

namespace volmorph::detail {

/// Sampler::sample(acc, p), p in index space. For BoxSampler, when the 2^3 values it reads lie in
/// one leaf (7 of every 8 positions per axis), they are read from that leaf's buffer, or are one
/// tile's value, instead of by eight accessor lookups; the interpolation is still BoxSampler's
/// own, so the result is the same bit for bit. This read is the sdf-mode frame's hottest.
template <typename Sampler, typename Accessor>
typename Accessor::ValueType sample(Accessor& acc, const openvdb::Vec3R& p)
{
    if constexpr (std::is_same_v<Sampler, openvdb::tools::BoxSampler>) {
        const openvdb::Coord ijk = openvdb::Coord::floor(p);
        if ((ijk.x() & 7) != 7 && (ijk.y() & 7) != 7 && (ijk.z() & 7) != 7) {
            using Value = typename Accessor::ValueType;
            Value data[2][2][2];
            if (const auto* leaf = acc.probeConstLeaf(ijk)) {
                const openvdb::Index o = leaf->coordToOffset(ijk);
                for (openvdb::Index i = 0; i < 2; ++i)
                    for (openvdb::Index j = 0; j < 2; ++j)
                        for (openvdb::Index k = 0; k < 2; ++k)
                            data[i][j][k] = leaf->getValue(o + (i << 6) + (j << 3) + k);
            } else {
                const Value v = acc.getValue(ijk); // a tile or the background: one value for all 8
                for (auto& plane : data)
                    for (auto& row : plane) row[0] = row[1] = v;
            }
            return openvdb::tools::BoxSampler::trilinearInterpolation(data, p - ijk.asVec3d());
        }
    }
    return Sampler::sample(acc, p);
}

} // namespace volmorph::detail
