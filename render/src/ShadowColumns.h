// Rays marched once each through the volume, keeping the transmittance along them: the storage
// both deep shadow maps share (Lokovic and Veach 2000). ShadowMap's rays are parallel (a
// directional light), PointShadowMap's leave a point light. A ray is marched from where it first
// meets the occupied region to where the volume has absorbed it, its transmittance taken every
// step, and stored as Lokovic and Veach store a visibility function: the fewest knots whose
// piecewise-linear interpolation stays within kTolerance of every step's value (a greedy cone of
// feasible slopes). Transmittance decays smoothly inside a medium, so a ray needs a few dozen knots
// at any voxel size, where every step would be some hundreds at 1000 voxels across: the maps grow
// with the region's cross-section, not its volume.
#pragma once

#include "GridReaders.h"

#include <volmorph/render/Props.h>

#include <openvdb/util/NullInterrupter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
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
    const Props* props =
        nullptr; ///< occluders of the rays (their shadows on the volume); may be null
};

/// The occupied region's box (the mask's active voxels), one voxel wider, as its 8 corners in world
/// space: what a shadow map's rays must cover.
std::array<Vec3d, 8> occupiedCorners(const openvdb::FloatGrid& density,
                                     const openvdb::BoolGrid& mask);

class ShadowColumns {
public:
    /// Ray c of `count` starts at world point `start` and goes along unit `direction`; rayOf(c,
    /// start, direction) says where. Each is marched for `length` world units, its transmittance
    /// taken every `spacing` world units from its start; in parallel, deterministically. Rays are
    /// skipped once the interrupter asks to stop (the caller checks it and discards the result).
    /// With props, a ray is dark from its first prop on, looked for from the light: `lightBehind`
    /// world units behind each ray's start (infinity for a directional light).
    using RayOf = std::function<void(size_t c, Vec3d& start, Vec3d& direction)>;
    ShadowColumns(const MarchInputs& in, size_t count, const RayOf& rayOf, double length,
                  double spacing, double lightBehind);

    /// The transmittance of ray c at `steps` spacings from its start: 1 before its stored span,
    /// its final transmittance after it, linear between knots; 0 from its first prop on.
    double along(size_t c, double steps) const
    {
        const Span& span = mSpans[c];
        if (steps >= double(span.dark)) return 0.0;
        const double x = steps - double(span.first); // steps from the span's first
        if (x <= -1.0) return 1.0;
        if (span.count == 0) return x >= 0.0 ? double(span.last) : lerp(1.0, span.last, x + 1.0);
        const Knot* knots = mKnots.data() + span.offset;
        if (x < 0.0) return lerp(1.0, value(knots[0]), x + 1.0);
        const Knot& end = knots[span.count - 1];
        if (x >= double(end.step))
            return x >= double(end.step) + 1.0 ? double(span.last)
                                               : lerp(value(end), span.last, x - double(end.step));
        const Knot* hi =
            std::upper_bound(knots, knots + span.count, x,
                             [](double v, const Knot& k) { return v < double(k.step); });
        const Knot* lo = hi - 1;
        return lerp(value(*lo), value(*hi), (x - double(lo->step)) / double(hi->step - lo->step));
    }

    /// Bilinear across a lattice of rays (ray first + j width + i for 0 <= i < width and 0 <= j <
    /// height; beyond it the transmittance is 1) at lattice coordinates (a, b), `steps` along.
    double across(size_t first, int width, int height, double a, double b, double steps) const
    {
        const double fa = std::floor(a), fb = std::floor(b);
        const int i = int(fa), j = int(fb);
        const double u = a - fa, v = b - fb;
        auto ray = [&](int ci, int cj) __attribute__((always_inline))
        {
            if (ci < 0 || cj < 0 || ci >= width || cj >= height) return 1.0;
            return along(first + size_t(cj) * size_t(width) + size_t(ci), steps);
        };
        return (1.0 - v) * ((1.0 - u) * ray(i, j) + u * ray(i + 1, j)) +
               v * ((1.0 - u) * ray(i, j + 1) + u * ray(i + 1, j + 1));
    }

    size_t bytes() const { return mSpans.size() * sizeof(Span) + mKnots.size() * sizeof(Knot); }

    /// The largest error of the knots' interpolation against the steps' transmittance.
    static constexpr double kTolerance = 2.5e-4;

private:
    struct Knot {
        uint16_t step;  ///< steps from the span's first
        uint16_t value; ///< transmittance, 16-bit fixed point
    };
    static double value(const Knot& k) { return double(k.value) * (1.0 / 65535.0); }
    static double lerp(double a, double b, double w) { return a + (b - a) * w; }

    struct Column {
        int first = 0;     ///< step index of the first knot
        float last = 1.0f; ///< the transmittance past the stored span
        float dark = std::numeric_limits<float>::infinity(); ///< steps to its first prop
        std::vector<Knot> knots;
    };
    struct Span {         ///< a column in mKnots
        int first, count; ///< step index of its first knot, and how many knots
        float last;       ///< the transmittance past its last knot
        float dark;       ///< steps from the start to its first prop (-inf: before the start)
        uint64_t offset;
    };

    /// One ray: the transmittance at each step from `start` along `direction` for `length`, into
    /// `steps` (from column.first on).
    static void march(Intersector& inter, DensityReader& acc, const MarchInputs& in,
                      const Vec3d& start, const Vec3d& direction, double length, double spacing,
                      Column& column, std::vector<float>& steps);
    /// The knots of `steps` (at most 65535 steps are kept: a ray longer than that inside the
    /// region, past some 37,000 voxels across, keeps its value there).
    static void compress(const std::vector<float>& steps, Column& column);
    /// Appends a batch of marched columns to the packed array (and frees theirs).
    void pack(std::vector<Column>& columns);

    std::vector<Span> mSpans;
    std::vector<Knot> mKnots;
};

} // namespace volmorph::render
