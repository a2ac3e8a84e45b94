#include <volmorph/render/EnvironmentMap.h>

#include <volmorph/render/Output.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace volmorph::render {
namespace {

/// The index of the bin of `cdf` (bins + 1 non-decreasing values) holding `value`: the last i with
/// cdf[i] <= value, at most bins - 1.
template <typename T>
size_t binOf(const T* cdf, size_t bins, T value)
{
    const T* it = std::upper_bound(cdf, cdf + bins + 1, value);
    const size_t i = it == cdf ? 0 : size_t(it - cdf) - 1;
    return std::min(i, bins - 1);
}

} // namespace

EnvironmentMap::EnvironmentMap(int width, int height, std::vector<float> rgb)
    : mWidth(width), mHeight(height), mRgb(std::move(rgb))
{
    const size_t w = size_t(std::max(width, 0)), h = size_t(std::max(height, 0));
    if (w == 0 || h == 0 || mRgb.size() != 3 * w * h)
        throw std::invalid_argument("an environment map needs width x height RGB pixels");
    for (float& v : mRgb) {
        if (!std::isfinite(v))
            throw std::invalid_argument("an environment map's pixels must be finite numbers");
        v = std::max(v, 0.0f);
    }
    mCosTheta.resize(h + 1);
    for (size_t j = 0; j <= h; ++j) mCosTheta[j] = std::cos(M_PI * double(j) / double(h));
    mCosTheta[h] = -1.0;
    mRowCdf.assign(h + 1, 0.0);
    mColumnCdf.assign(h * (w + 1), 0.0f);
    std::vector<double> row(w + 1);
    for (size_t j = 0; j < h; ++j) {
        const double solidAngle = 2.0 * M_PI / double(w) * (mCosTheta[j] - mCosTheta[j + 1]);
        row[0] = 0.0;
        for (size_t i = 0; i < w; ++i) row[i + 1] = row[i] + luminance(j * w + i) * solidAngle;
        float* cdf = &mColumnCdf[j * (w + 1)];
        for (size_t i = 0; i <= w; ++i)
            cdf[i] = row[w] > 0.0 ? float(row[i] / row[w]) : float(double(i) / double(w));
        cdf[w] = 1.0f;
        mRowCdf[j + 1] = mRowCdf[j] + row[w];
    }
    mTotal = mRowCdf[h];
}

std::shared_ptr<const EnvironmentMap> EnvironmentMap::read(const std::filesystem::path& path)
{
    const ChannelImage image = readChannels(path);
    const size_t pixels = size_t(image.width) * size_t(image.height), n = image.names.size();
    // R, G and B by name, else the first three channels, else the first as grey.
    size_t from[3];
    for (size_t c = 0; c < 3; ++c) {
        const int named = image.channel(std::string(1, "RGB"[c]));
        from[c] = named >= 0 ? size_t(named) : n >= 3 ? c : 0;
    }
    std::vector<float> rgb(3 * pixels);
    for (size_t p = 0; p < pixels; ++p)
        for (size_t c = 0; c < 3; ++c) rgb[3 * p + c] = image.values[n * p + from[c]];
    try {
        return std::make_shared<const EnvironmentMap>(image.width, image.height, std::move(rgb));
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(e.what());
    }
}

double EnvironmentMap::luminance(size_t pixel) const
{
    const float* c = &mRgb[3 * pixel];
    return 0.2126 * double(c[0]) + 0.7152 * double(c[1]) + 0.0722 * double(c[2]);
}

size_t EnvironmentMap::pixelOf(const Vec3d& d) const
{
    const double theta = std::acos(std::clamp(d.y(), -1.0, 1.0));
    const double u = std::atan2(d.z(), d.x()) / (2.0 * M_PI) + 0.5;
    const int j = std::clamp(int(theta / M_PI * mHeight), 0, mHeight - 1);
    const int i = std::clamp(int(u * mWidth), 0, mWidth - 1);
    return size_t(j) * size_t(mWidth) + size_t(i);
}

Vec3d EnvironmentMap::radiance(const Vec3d& direction) const
{
    const float* c = &mRgb[3 * pixelOf(direction)];
    return Vec3d(c[0], c[1], c[2]);
}

double EnvironmentMap::pdf(const Vec3d& direction) const
{
    return mTotal > 0.0 ? luminance(pixelOf(direction)) / mTotal : 0.0;
}

Vec3d EnvironmentMap::sample(double u1, double u2, double& pdf) const
{
    pdf = 0.0;
    if (mTotal <= 0.0) return Vec3d(0.0, 1.0, 0.0);
    const size_t w = size_t(mWidth), h = size_t(mHeight);
    // A row by its weight, then a column within it; each number's place inside its bin is reused
    // for the position inside the pixel.
    const double rowValue = u1 * mTotal;
    const size_t j = binOf(mRowCdf.data(), h, rowValue);
    const double s = (rowValue - mRowCdf[j]) / (mRowCdf[j + 1] - mRowCdf[j]);
    const float* cdf = &mColumnCdf[j * (w + 1)];
    const size_t i = binOf(cdf, w, float(u2));
    const double width = double(cdf[i + 1]) - double(cdf[i]);
    const double t = width > 0.0 ? std::clamp((u2 - double(cdf[i])) / width, 0.0, 1.0) : 0.5;
    // Uniform over the pixel's solid angle: cos theta uniform between the row's boundaries.
    const double cosTheta =
        mCosTheta[j] + (mCosTheta[j + 1] - mCosTheta[j]) * std::clamp(s, 0.0, 1.0);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double phi = 2.0 * M_PI * ((double(i) + t) / double(w) - 0.5);
    pdf = luminance(j * w + i) / mTotal;
    return Vec3d(sinTheta * std::cos(phi), cosTheta, sinTheta * std::sin(phi));
}

} // namespace volmorph::render
