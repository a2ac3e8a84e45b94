// Value functions of the scene's settings; parsing lives in SceneParser.cpp and its table units.
#include <volmorph/Scene.h>

#include <volmorph/Frames.h>

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

bool isNiftiFile(const std::filesystem::path& file)
{
    const std::string name = file.filename().string();
    auto endsWith = [&name](const std::string& end) {
        return name.size() >= end.size() &&
               name.compare(name.size() - end.size(), end.size(), end) == 0;
    };
    return endsWith(".nii") || endsWith(".nii.gz");
}

std::filesystem::path ObjectSpec::volumeAt(int frame) const
{
    if (!isSequence()) return volume;
    auto held = std::upper_bound(volumeFrames.begin(), volumeFrames.end(), frame);
    const int input = held == volumeFrames.begin() ? volumeFrames.front() : *std::prev(held);
    return frameFileName(volume.string(), input);
}

Scene sceneAtFrame(const Scene& scene, int frame)
{
    Scene s = scene;
    for (ObjectSpec* o : {&s.source, &s.target})
        if (o->isSequence()) {
            o->volume = o->volumeAt(frame);
            o->volumeFrames.clear();
        }
    return s;
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
