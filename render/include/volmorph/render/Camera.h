// Cameras of volmorph's renderer. World units; fov in degrees (horizontal, as vdb_render's -fov).
#pragma once

#include <volmorph/core/Math.h>

namespace volmorph::render {

struct Ray {
    Vec3d origin, direction; ///< direction has unit length
};

/// A look-at camera, perspective (horizontal field of view) or orthographic (width in world units).
class Camera {
public:
    enum class Projection { Perspective, Orthographic };

    Camera(Projection projection, const Vec3d& eye, const Vec3d& lookat, const Vec3d& up,
           double fovDegrees, double orthoWidth, int width, int height);

    /// The ray through image position (x, y) in pixels: (0, 0) is the top-left corner of the
    /// top-left pixel, (width, height) the bottom-right corner of the last one.
    Ray ray(double x, double y) const;

    /// World to camera space (x right, y up, looking along -z), as OpenEXR's worldToCamera,
    /// written for column vectors p_camera = M p_world.
    Mat4d worldToCamera() const;
    /// World to normalized device coordinates: x and y in [0, 1] across the image (y down), as
    /// OpenEXR's worldToNDC (perspective divide by w), column vectors.
    Mat4d worldToNdc() const;

    /// The unit view direction (world): a ray's depth is its distance times ray.direction .
    /// forward.
    const Vec3d& forward() const { return mForward; }
    int width() const { return mWidth; }
    int height() const { return mHeight; }

private:
    Projection mProjection;
    Vec3d mEye, mForward, mRight, mUp;
    double mHalfWidth,
        mHalfHeight; ///< of the image plane at distance 1 (perspective) or in world units
    int mWidth, mHeight;
};

} // namespace volmorph::render
