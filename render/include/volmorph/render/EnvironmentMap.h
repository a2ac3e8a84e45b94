// A sky from a lat-long (equirectangular) HDR image: its radiance by direction, and directions
// drawn in proportion to it (importance sampling), so that a small bright sun in the map is found
// by next-event estimation as a sun light is.
//
// Orientation (world, y up): a pixel row's polar angle from +y is theta = pi v (v from 0 at the top
// row to 1 at the bottom), its azimuth phi = 2 pi (u - 1/2) (u from 0 at the left column to 1 at
// the right), direction (sin theta cos phi, cos theta, sin theta sin phi): the image's centre looks
// along +x, three quarters across along +z. This is how Blender maps the same image onto its z-up
// world when that world is volmorph's turned by 90 degrees about x (tests/bench/cycles_render.py).
//
// The radiance is constant over each pixel (no filtering): exactly the function the sampling
// distribution is built from. A pixel is drawn with probability its luminance times its solid angle
// over the map's total, then a direction uniformly over the pixel's solid angle, so the density per
// steradian is the pixel's luminance over the total: a map of constant colour is sampled uniformly
// over the sphere, and radiance / density is constant over any region of one colour.
#pragma once

#include <volmorph/core/Math.h>

#include <filesystem>
#include <memory>
#include <vector>

namespace volmorph::render {

class EnvironmentMap {
public:
    /// From linear RGB pixels (3 floats each, row-major, top row first). Negative values count as
    /// 0; NaN and infinity are refused (std::invalid_argument).
    EnvironmentMap(int width, int height, std::vector<float> rgb);

    /// Reads a lat-long image through OpenImageIO (EXR, HDR, ...: its first three channels as
    /// linear RGB, or one channel as grey). Throws std::runtime_error with the reason.
    static std::shared_ptr<const EnvironmentMap> read(const std::filesystem::path& path);

    int width() const { return mWidth; }
    int height() const { return mHeight; }

    /// The radiance arriving from unit world direction `direction` (travelling against it).
    Vec3d radiance(const Vec3d& direction) const;

    /// A unit world direction drawn from the map's distribution with uniform numbers u1, u2 in
    /// [0, 1); `pdf` gets its density per steradian (0 for a black map: no direction).
    Vec3d sample(double u1, double u2, double& pdf) const;

    /// The density per steradian with which sample() draws unit `direction`.
    double pdf(const Vec3d& direction) const;

    /// The integral of luminance over the sphere (the normalization of the density).
    double totalPower() const { return mTotal; }

private:
    size_t pixelOf(const Vec3d& direction) const;
    double luminance(size_t pixel) const;

    int mWidth, mHeight;
    std::vector<float> mRgb;
    std::vector<double> mRowCdf;   ///< height + 1: the rows' weights, accumulated, from 0
    std::vector<float> mColumnCdf; ///< per row, width + 1: its pixels' weights over its total
    std::vector<double> mCosTheta; ///< height + 1: cos of each row boundary's polar angle
    double mTotal = 0.0;
};

} // namespace volmorph::render
