// Value functions of the scene types; parsing lives in SceneParser.cpp.
#include <volmorph/Scene.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>

namespace volmorph {

Mat4d ObjectTransform::matrix() const
{
    // OpenVDB matrices act on row vectors (p' = p M), so the chain below reads left to right in
    // the order the operations apply: scale, rotate X, Y, Z, translate.
    Mat4d m = Mat4d::identity();
    m.preScale(scale); // identity scaled; order of pre/post only matters once m is non-trivial
    m.postRotate(openvdb::math::X_AXIS, rotateRadians.x());
    m.postRotate(openvdb::math::Y_AXIS, rotateRadians.y());
    m.postRotate(openvdb::math::Z_AXIS, rotateRadians.z());
    m.postTranslate(translate);
    return m;
}

Vec3d ObjectTransform::apply(const Vec3d& p) const
{
    return matrix().transform(p);
}

bool ObjectTransform::isIdentity() const
{
    return translate == Vec3d(0.0) && rotateRadians == Vec3d(0.0) && scale == Vec3d(1.0);
}

const char* toString(FeatureType type)
{
    switch (type) {
    case FeatureType::Point:
        return "point";
    case FeatureType::Segment:
        return "segment";
    case FeatureType::Rectangle:
        return "rectangle";
    case FeatureType::Box:
        return "box";
    }
    return "?";
}

namespace {

/// The two keys around `frame` and the weight of the second; the same key twice outside them.
template <typename Key>
void around(const std::vector<Key>& keys, int frame, const Key*& a, const Key*& b, double& u)
{
    a = b = &keys.front();
    u = 0.0;
    if (frame <= keys.front().frame) return;
    a = b = &keys.back();
    if (frame >= keys.back().frame) return;
    for (size_t i = 1; i < keys.size(); ++i) {
        if (frame <= keys[i].frame) {
            a = &keys[i - 1];
            b = &keys[i];
            u = double(frame - a->frame) / double(b->frame - a->frame);
            return;
        }
    }
}

Vec3d lerp(const Vec3d& a, const Vec3d& b, double u)
{
    return a + (b - a) * u;
}

/// Linear interpolation of two directions, renormalized (keys may not be opposite: the parser
/// refuses that).
Vec3d lerpDirection(const Vec3d& a, const Vec3d& b, double u)
{
    const Vec3d d = lerp(a.unit(), b.unit(), u);
    return d.length() > 1e-12 ? d.unit() : a.unit();
}

} // namespace

CameraSpec CameraSpec::at(int frame) const
{
    CameraSpec c = *this;
    if (keys.empty()) return c;
    const CameraKey *a, *b;
    double u;
    around(keys, frame, a, b, u);
    c.eye = lerp(a->eye, b->eye, u);
    c.lookat = lerp(a->lookat, b->lookat, u);
    c.up = lerpDirection(a->up, b->up, u);
    c.fovDegrees = a->fovDegrees + (b->fovDegrees - a->fovDegrees) * u;
    c.orthoWidth = a->orthoWidth + (b->orthoWidth - a->orthoWidth) * u;
    c.keys.clear();
    return c;
}

LightSpec LightSpec::at(int frame) const
{
    LightSpec l = *this;
    if (keys.empty()) return l;
    const LightKey *a, *b;
    double u;
    around(keys, frame, a, b, u);
    l.direction = lerpDirection(a->direction, b->direction, u);
    l.position = lerp(a->position, b->position, u);
    l.color = lerp(a->color, b->color, u);
    l.intensity = a->intensity + (b->intensity - a->intensity) * u;
    l.keys.clear();
    return l;
}

double FramesSpec::t(int frame) const
{
    if (last == first) return 0.0;
    return double(frame - first) / double(last - first);
}

} // namespace volmorph
