// The vector and matrix types shared by the engine and the renderer: OpenVDB's, named once here.
// Points and directions are in world units unless a name says otherwise (index space: voxels).
#pragma once

#include <openvdb/math/Mat4.h>
#include <openvdb/math/Vec2.h>
#include <openvdb/math/Vec3.h>

#include <cstdint>

namespace volmorph {

using Vec2d = openvdb::math::Vec2d; ///< texture coordinates (u, v)
using Vec2f = openvdb::math::Vec2s;
using Vec3d = openvdb::math::Vec3d;
using Vec3f = openvdb::math::Vec3s;
using Mat4d = openvdb::math::Mat4d;
using Vec3I = openvdb::math::Vec3<uint32_t>; ///< a triangle's vertex indices

} // namespace volmorph
