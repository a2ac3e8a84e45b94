// Rays marched once each through the volume, keeping the transmittance at even steps along them:
// the storage both deep shadow maps share (Lokovic and Veach 2000). ShadowMap's rays are parallel
// (a directional light), PointShadowMap's leave a point light. A ray stores only the span from
// where it first meets the occupied region to where the volume has absorbed it, packed into one
// array.
#pragma once

#include "GridReaders.h"

#include <openvdb/util/NullInterrupter.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace volmorph::render {

/// What a march through the volume reads.
struct MarchInputs {
    const openvdb::FloatGrid& density;
    const PaddedLeaves& padded;
    const openvdb::BoolGrid& mask; ///< rayMask's empty-space mask
    bool levelSet;
    double sigmaPerVoxel; ///< extinction per index unit at density 1
    openvdb::util::NullInterrupter* interrupter;
};

class ShadowColumns {
public:
    /// Ray c of `count` starts at world point `start` and goes along unit `direction`; rayOf(c,
    /// start, direction) says where. Each is marched for `length` world units, its transmittance
    /// kept every `spacing` world units from its start; in parallel, deterministically. Rays are
    /// skipped once the interrupter asks to stop (the caller checks it and discards the result).
    using RayOf = std::function<void(size_t c, Vec3d& start, Vec3d& direction)>;
    ShadowColumns(const MarchInputs& in, size_t count, const RayOf& rayOf, double length,
                  double spacing);

    /// The transmittance of ray c at its k-th step (k spacings from its start): 1 before its
    /// stored span, its final transmittance after it.
    double at(size_t c, int k) const
    {
        const Span& span = mSpans[c];
        const int i = k - span.first;
        return i < 0            ? 1.0
               : i < span.count ? double(mData[span.offset + size_t(i)]) * kUnit
                                : double(span.last);
    }

    /// Linear interpolation along ray c at fractional step k + w.
    double along(size_t c, int k, double w) const
    {
        return (1.0 - w) * at(c, k) + w * at(c, k + 1);
    }

    size_t bytes() const { return mSpans.size() * sizeof(Span) + mData.size() * sizeof(uint16_t); }

private:
    static constexpr double kUnit = 1.0 / 65535.0; ///< the transmittance of one stored step

    struct Column {
        int first = 0;     ///< step index of values[0]
        float last = 1.0f; ///< the transmittance past the stored span
        std::vector<uint16_t> values;
    };
    struct Span {         ///< a column in mData
        int first, count; ///< step index of its first value, and how many
        float last;       ///< the transmittance past its last value
        uint64_t offset;
    };

    /// One ray: the transmittance at each step from `start` along `direction` for `length`.
    static void march(Intersector& inter, DensityReader& acc, const MarchInputs& in,
                      const Vec3d& start, const Vec3d& direction, double length, double spacing,
                      Column& column);
    /// Appends a batch of marched columns to the packed array (and frees theirs).
    void pack(std::vector<Column>& columns);

    std::vector<Span> mSpans;
    std::vector<uint16_t> mData;
};

} // namespace volmorph::render
