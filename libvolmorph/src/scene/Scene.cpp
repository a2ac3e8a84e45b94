// Value functions of the scene's settings; parsing lives in SceneParser.cpp and its table units.
#include <volmorph/Scene.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
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
    static constexpr const char* kNames[] = {"point", "segment", "rectangle", "box"};
    static_assert(std::size(kNames) == size_t(FeatureType::Box) + 1, "a name for each type");
    return kNames[size_t(type)];
}

double FramesSpec::t(int frame) const
{
    if (last == first) return 0.0;
    return double(frame - first) / double(last - first);
}

} // namespace volmorph
