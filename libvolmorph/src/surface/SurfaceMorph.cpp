#include <volmorph/SurfaceMorph.h>

#include "Correspondence.h"
#include "RigidInterpolation.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <optional>

namespace volmorph {

const char* name(Correspondence c)
{
    switch (c) {
    case Correspondence::Auto:
        return "auto";
    case Correspondence::Identity:
        return "identity";
    case Correspondence::Star:
        return "star";
    case Correspondence::Sphere:
        return "sphere";
    case Correspondence::Disk:
        return "disk";
    }
    return "?";
}

const char* name(SurfaceInterpolation i)
{
    return i == SurfaceInterpolation::Arap ? "arap" : "linear";
}

Mesh SurfaceFrame::mesh() const
{
    Mesh m;
    m.points.reserve(points.size());
    for (const Vec3d& p : points) m.points.emplace_back(Vec3f(p));
    m.triangles = triangles;
    m.colors = colors;
    m.uvs = uvs;
    m.report.inputTriangles = triangles.size();
    analyzeTopology(m);
    return m;
}

struct SurfaceMorpher::Impl {
    detail::Corresponded sides;
    std::optional<detail::RigidInterpolation> rigid; // "arap"
};

SurfaceMorpher::SurfaceMorpher(const Mesh& source, const Mesh& target, const SurfaceSpec& spec,
                               Interrupter* interrupter)
    : mImpl(std::make_unique<Impl>())
{
    mImpl->sides = detail::correspond(source, target, spec, interrupter);
    throwIfInterrupted(interrupter);
    const detail::Corresponded& s = mImpl->sides;
    if (spec.interpolation == SurfaceInterpolation::Arap)
        mImpl->rigid.emplace(s.source, s.target, s.triangles);
}

SurfaceMorpher::~SurfaceMorpher() = default;
SurfaceMorpher::SurfaceMorpher(SurfaceMorpher&&) noexcept = default;
SurfaceMorpher& SurfaceMorpher::operator=(SurfaceMorpher&&) noexcept = default;

namespace {

/// d s / d t is taken as 0 where 1 - grad tau . (b - a) is below this (a fold).
constexpr double kLeastSlope = 1e-3;

/// Each vertex's own tau s (the root of g(s) = s - tau(a + s (b - a)) in [0, 1]: g(0) <= 0 <=
/// g(1)) and d s / d t.
void vertexTimes(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, const PlaceTime& shape,
                 std::vector<double>& tau, std::vector<double>& rate)
{
    tau.resize(a.size());
    rate.resize(a.size());
    tbb::parallel_for(size_t(0), a.size(), [&](size_t i) {
        const Vec3d d = b[i] - a[i];
        double lo = 0.0, hi = 1.0, s = shape(a[i]).tau;
        PlaceTau at = shape(a[i] + s * d);
        for (int step = 0; step < 100; ++step) {
            const double g = s - at.tau;
            if (std::abs(g) < 1e-14 || hi - lo < 1e-15) break;
            (g < 0.0 ? lo : hi) = s;
            const double slope = 1.0 - at.gradient.dot(d);
            double next = slope > 0.0 ? s - g / slope : 0.5 * (lo + hi);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            s = next;
            at = shape(a[i] + s * d);
        }
        const double slope = 1.0 - at.gradient.dot(d);
        tau[i] = s;
        rate[i] = slope > kLeastSlope ? at.dt / slope : 0.0;
    });
}

/// Colours and texture coordinates at each vertex's colour tau (`colorTau(vertex)`).
template <typename ColorTau>
void paint(const detail::Corresponded& s, const ColorTau& colorTau, SurfaceFrame& f)
{
    f.colors.resize(s.sourceColors.size());
    for (size_t i = 0; i < f.colors.size(); ++i) {
        const double c = colorTau(i);
        f.colors[i] = Vec3f((1.0 - c) * Vec3d(s.sourceColors[i]) + c * Vec3d(s.targetColors[i]));
    }
    for (size_t k = 0; k < s.sourceUVs.size(); ++k) {
        const double c = colorTau(s.triangles[k / 3][int(k % 3)]);
        f.uvs.emplace_back((1.0 - c) * s.sourceUVs[k] + c * s.targetUVs[k]);
        f.sourceUVs.emplace_back(s.sourceUVs[k]);
        f.targetUVs.emplace_back(s.targetUVs[k]);
    }
}

} // namespace

SurfaceFrame SurfaceMorpher::frame(double shapeTau, double colorTau) const
{
    const detail::Corresponded& s = mImpl->sides;
    SurfaceFrame f;
    f.triangles = s.triangles;
    if (mImpl->rigid) {
        mImpl->rigid->positions(shapeTau, f.points, f.velocity);
    } else {
        f.points.resize(s.source.size());
        f.velocity.resize(s.source.size());
        for (size_t i = 0; i < s.source.size(); ++i) {
            f.points[i] = (1.0 - shapeTau) * s.source[i] + shapeTau * s.target[i];
            f.velocity[i] = s.target[i] - s.source[i];
        }
    }
    paint(
        s, [colorTau](size_t) { return colorTau; }, f);
    return f;
}

SurfaceFrame SurfaceMorpher::frame(const PlaceTime& shape, const PlaceTime& color) const
{
    const detail::Corresponded& s = mImpl->sides;
    SurfaceFrame f;
    f.triangles = s.triangles;
    std::vector<double> tau, rate;
    vertexTimes(s.source, s.target, shape, tau, rate);
    if (mImpl->rigid) {
        mImpl->rigid->positions(tau, rate, f.points, f.velocity);
    } else {
        f.points.resize(s.source.size());
        f.velocity.resize(s.source.size());
        for (size_t i = 0; i < s.source.size(); ++i) {
            f.points[i] = s.source[i] + tau[i] * (s.target[i] - s.source[i]);
            f.velocity[i] = (s.target[i] - s.source[i]) * rate[i];
        }
    }
    std::vector<double> colorTau(f.points.size());
    tbb::parallel_for(size_t(0), f.points.size(),
                      [&](size_t i) { colorTau[i] = color(f.points[i]).tau; });
    paint(
        s, [&colorTau](size_t i) { return colorTau[i]; }, f);
    return f;
}

Correspondence SurfaceMorpher::correspondence() const
{
    return mImpl->sides.used;
}
size_t SurfaceMorpher::vertexCount() const
{
    return mImpl->sides.source.size();
}
size_t SurfaceMorpher::triangleCount() const
{
    return mImpl->sides.triangles.size();
}
size_t SurfaceMorpher::crossings() const
{
    return mImpl->sides.crossings;
}
std::optional<std::pair<Vec3d, Vec3d>> SurfaceMorpher::kernels() const
{
    return mImpl->sides.kernels;
}
std::optional<std::pair<double, double>> SurfaceMorpher::stretchEfficiency() const
{
    return mImpl->sides.stretch;
}

} // namespace volmorph
