// How an object (a mesh, a volume, a prop) is placed in the world: shared by the engine's inputs
// and the renderer's props.
#pragma once

#include <volmorph/core/Math.h>

namespace volmorph {

/// Object-to-world placement: scale, then rotate about X, then Y, then Z, then translate.
struct ObjectTransform {
    Vec3d translate{0.0, 0.0, 0.0}; ///< world units
    Vec3d rotateRadians{0.0, 0.0, 0.0};
    Vec3d scale{1.0, 1.0, 1.0}; ///< uniform or per axis; every component > 0

    /// Column-vector convention p' = M p (OpenVDB stores it transposed: use transform() to apply).
    Mat4d matrix() const;
    Vec3d apply(const Vec3d& p) const;
    bool isIdentity() const;
};

} // namespace volmorph
