// A leaf with the one-voxel layer of its 26 neighbour leaves around it, as a dense 10^3 block:
// copied once per leaf, so that each voxel's 26 neighbour reads are array reads, not tree probes
// (VelocityReach's layers, ExtendedDistance's shared surface points).
#pragma once

#include <openvdb/openvdb.h>

#include <array>

namespace volmorph::detail::apron {

inline constexpr int kSide = 10;
inline constexpr int kCount = kSide * kSide * kSide;

/// The dense index of the leaf's local (x, y, z), each in -1..8.
inline int index(int x, int y, int z)
{
    return ((x + 1) * kSide + (y + 1)) * kSide + (z + 1);
}
inline int index(openvdb::Index n)
{
    return index(int(n >> 6), int((n >> 3) & 7), int(n & 7));
}

/// The dense offsets of a voxel's 27 neighbours (itself included), x, y, z each from -1 to 1.
inline const std::array<int, 27>& neighbours()
{
    static const std::array<int, 27> offsets = [] {
        std::array<int, 27> o{};
        int k = 0;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) o[size_t(k++)] = (dx * kSide + dy) * kSide + dz;
        return o;
    }();
    return offsets;
}

/// For the leaf at `origin` and each of its 26 neighbours for which bind(neighbour's origin) is
/// true, calls copy(n, i) for each of that leaf's voxels n within one voxel of `origin`'s leaf,
/// i its dense index.
template <typename Bind, typename Copy>
void gather(const openvdb::Coord& origin, Bind&& bind, Copy&& copy)
{
    const auto lo = [](int d) { return d < 0 ? 7 : 0; };
    const auto hi = [](int d) { return d > 0 ? 0 : 7; };
    for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
                if (!bind(origin.offsetBy(8 * dx, 8 * dy, 8 * dz))) continue;
                for (int x = lo(dx); x <= hi(dx); ++x)
                    for (int y = lo(dy); y <= hi(dy); ++y)
                        for (int z = lo(dz); z <= hi(dz); ++z)
                            copy(openvdb::Index((x << 6) | (y << 3) | z),
                                 index(x + 8 * dx, y + 8 * dy, z + 8 * dz));
            }
}

} // namespace volmorph::detail::apron
