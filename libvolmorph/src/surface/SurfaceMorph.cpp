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
    m.report.inputTriangles = triangles.size();
    analyzeTopology(m);
    return m;
}

struct SurfaceMorpher::Impl {
    detail::Corresponded sides;
    std::optional<detail::RigidInterpolation> rigid; // "arap"
};

namespace {

/// A side without vertex colours takes grey when the other has them (Voxelize.cpp's grey).
void matchColors(Mesh& mesh, const Mesh& other)
{
    if (mesh.colors.empty() && !other.colors.empty())
        mesh.colors.assign(mesh.points.size(), Vec3f(0.8f));
}

} // namespace

SurfaceMorpher::SurfaceMorpher(Mesh source, Mesh target, const SurfaceSpec& spec)
    : mImpl(std::make_unique<Impl>())
{
    mImpl->sides = detail::correspond(std::move(source), std::move(target), spec);
    matchColors(mImpl->sides.source, mImpl->sides.target);
    matchColors(mImpl->sides.target, mImpl->sides.source);
    if (spec.interpolation == SurfaceInterpolation::Arap)
        mImpl->rigid.emplace(mImpl->sides.source, mImpl->sides.target);
}

SurfaceMorpher::~SurfaceMorpher() = default;
SurfaceMorpher::SurfaceMorpher(SurfaceMorpher&&) noexcept = default;
SurfaceMorpher& SurfaceMorpher::operator=(SurfaceMorpher&&) noexcept = default;

SurfaceFrame SurfaceMorpher::frame(double shapeTau, double colorTau) const
{
    const Mesh& a = mImpl->sides.source;
    const Mesh& b = mImpl->sides.target;
    SurfaceFrame f;
    f.triangles = a.triangles;
    if (mImpl->rigid) {
        mImpl->rigid->positions(shapeTau, f.points, f.velocity);
    } else {
        f.points.resize(a.points.size());
        f.velocity.resize(a.points.size());
        for (size_t i = 0; i < a.points.size(); ++i) {
            const Vec3d p(a.points[i]), q(b.points[i]);
            f.points[i] = (1.0 - shapeTau) * p + shapeTau * q;
            f.velocity[i] = q - p;
        }
    }
    f.colors.resize(a.colors.size());
    for (size_t i = 0; i < a.colors.size(); ++i)
        f.colors[i] = Vec3f((1.0 - colorTau) * Vec3d(a.colors[i]) + colorTau * Vec3d(b.colors[i]));
    return f;
}

Correspondence SurfaceMorpher::correspondence() const
{
    return mImpl->sides.used;
}
size_t SurfaceMorpher::vertexCount() const
{
    return mImpl->sides.source.points.size();
}
size_t SurfaceMorpher::triangleCount() const
{
    return mImpl->sides.source.triangles.size();
}

} // namespace volmorph
