#include <volmorph/render/Camera.h>

#include <cmath>

namespace volmorph::render {

Camera::Camera(Projection projection, const Vec3d& eye, const Vec3d& lookat, const Vec3d& up,
               double fovDegrees, double orthoWidth, int width, int height)
    : mProjection(projection), mEye(eye), mWidth(width), mHeight(height)
{
    mForward = (lookat - eye).unit();
    mRight = mForward.cross(up).unit();
    mUp = mRight.cross(mForward);
    const double aspect = double(height) / double(width);
    mHalfWidth = projection == Projection::Perspective ? std::tan(0.5 * fovDegrees * M_PI / 180.0)
                                                       : 0.5 * orthoWidth;
    mHalfHeight = mHalfWidth * aspect;
}

Ray Camera::ray(double x, double y) const
{
    const double sx = (2.0 * x / mWidth - 1.0) * mHalfWidth;
    const double sy = (1.0 - 2.0 * y / mHeight) * mHalfHeight;
    if (mProjection == Projection::Orthographic) return {mEye + mRight * sx + mUp * sy, mForward};
    return {mEye, (mForward + mRight * sx + mUp * sy).unit()};
}

Mat4d Camera::worldToCamera() const
{
    // Rows: right, up, -forward; translation -R eye. Column-vector convention (M(i, j) = row i).
    Mat4d m = Mat4d::identity();
    const Vec3d back = -mForward;
    for (int j = 0; j < 3; ++j) {
        m(0, j) = mRight[j];
        m(1, j) = mUp[j];
        m(2, j) = back[j];
    }
    m(0, 3) = -mRight.dot(mEye);
    m(1, 3) = -mUp.dot(mEye);
    m(2, 3) = -back.dot(mEye);
    return m;
}

Mat4d Camera::worldToNdc() const
{
    // Camera space (looking along -z) to NDC: x_ndc = 0.5 + 0.5 x / (-z * hw) (perspective).
    Mat4d p = Mat4d::zero();
    if (mProjection == Projection::Perspective) {
        p(0, 0) = 0.5 / mHalfWidth;
        p(0, 2) = -0.5;
        p(1, 1) = -0.5 / mHalfHeight;
        p(1, 2) = -0.5;
        p(2, 3) = 1.0;  // z_ndc * w = 1: not used for depth here
        p(3, 2) = -1.0; // w = -z
    } else {
        p(0, 0) = 0.5 / mHalfWidth;
        p(0, 3) = 0.5;
        p(1, 1) = -0.5 / mHalfHeight;
        p(1, 3) = 0.5;
        p(2, 2) = -1.0;
        p(3, 3) = 1.0;
    }
    const Mat4d c = worldToCamera();
    Mat4d out = Mat4d::zero();
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) out(i, j) += p(i, k) * c(k, j);
    return out;
}

} // namespace volmorph::render
