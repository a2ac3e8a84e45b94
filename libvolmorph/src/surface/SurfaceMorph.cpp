#include <volmorph/SurfaceMorph.h>

#include "Correspondence.h"
#include "RigidInterpolation.h"

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
    f.colors.resize(s.sourceColors.size());
    for (size_t i = 0; i < f.colors.size(); ++i)
        f.colors[i] = Vec3f((1.0 - colorTau) * Vec3d(s.sourceColors[i]) +
                            colorTau * Vec3d(s.targetColors[i]));
    for (size_t k = 0; k < s.sourceUVs.size(); ++k) {
        f.uvs.emplace_back((1.0 - colorTau) * s.sourceUVs[k] + colorTau * s.targetUVs[k]);
        f.sourceUVs.emplace_back(s.sourceUVs[k]);
        f.targetUVs.emplace_back(s.targetUVs[k]);
    }
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
