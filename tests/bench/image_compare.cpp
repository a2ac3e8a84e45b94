// How far an image is from a reference render, over the pixels the reference covers (alpha above
// MIN_ALPHA, default 0.1):
// - the difference of relative luminance Y (Rec. 709 weights; 1 = white), mean and 99th percentile;
// - the relative RGB difference, sum |a - b| / sum b over the three channels of every covered pixel
//   (noise and bias), and the relative bias sum a / sum b - 1;
// - the relative RMSE: the root mean square of a - b over those channels, over the mean of b (the
//   noise measure of equal-RMSE speed comparisons);
// - the difference image's power at periods from 2 pixels to 3 voxels in any direction (a 2D DFT):
//   the shadow cache's lattice lies in the light's frame, so its stripes run at any angle.
// Used by striations.sh and cycles_compare.sh.
// usage: volmorph_bench_image_compare IMAGE.exr REFERENCE.exr PIXELS_PER_VOXEL [MIN_ALPHA]
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

struct Plane {
    int width = 0, height = 0;
    std::vector<float> rgba;
};

bool load(const std::string& path, Plane& plane)
{
    OIIO::ImageBuf buf(path);
    if (!buf.read(0, 0, true, OIIO::TypeDesc::FLOAT) || buf.nchannels() < 4) {
        std::fprintf(stderr, "%s: cannot read an RGBA image\n", path.c_str());
        return false;
    }
    plane.width = buf.spec().width;
    plane.height = buf.spec().height;
    plane.rgba.resize(size_t(plane.width) * plane.height * 4);
    buf.get_pixels(OIIO::ROI(0, plane.width, 0, plane.height, 0, 1, 0, 4), OIIO::TypeDesc::FLOAT,
                   plane.rgba.data());
    return true;
}

double luminance(const float* p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/// The power of `diff` (its mean square, by Parseval) carried by spatial frequencies whose period
/// lies between `shortest` and `longest` pixels in any direction: OpenImageIO's 2D FFT.
double bandPower(const std::vector<double>& diff, int width, int height, double shortest,
                 double longest)
{
    OIIO::ImageBuf src(OIIO::ImageSpec(width, height, 1, OIIO::TypeDesc::FLOAT));
    std::vector<float> values(diff.begin(), diff.end());
    src.set_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 1), OIIO::TypeDesc::FLOAT,
                   values.data());
    const OIIO::ImageBuf spectrum = OIIO::ImageBufAlgo::fft(src); // real and imaginary channels
    const double fMin = 1.0 / longest, fMax = 1.0 / shortest, n = double(width) * height;
    double power = 0.0;
    for (int ky = 0; ky < height; ++ky)
        for (int kx = 0; kx < width; ++kx) {
            const double fx = double(kx <= width / 2 ? kx : kx - width) / width;
            const double fy = double(ky <= height / 2 ? ky : ky - height) / height;
            const double f = std::hypot(fx, fy);
            if (f < fMin || f > fMax) continue;
            const double re = spectrum.getchannel(kx, ky, 0, 0),
                         im = spectrum.getchannel(kx, ky, 0, 1);
            power += (re * re + im * im) / n; // OIIO scales the transform by 1 / sqrt(n)
        }
    return power;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 4) {
        std::fprintf(stderr, "usage: %s IMAGE.exr REFERENCE.exr PIXELS_PER_VOXEL [MIN_ALPHA]\n",
                     argv[0]);
        return 2;
    }
    Plane image, reference;
    if (!load(argv[1], image) || !load(argv[2], reference)) return 1;
    if (image.width != reference.width || image.height != reference.height) {
        std::fprintf(stderr, "the images differ in size\n");
        return 1;
    }
    // Periods from 2 pixels (Nyquist) to 3 voxels: the shadow cache's lattice and its harmonics.
    const double pixelsPerVoxel = std::atof(argv[3]),
                 minAlpha = argc > 4 ? std::atof(argv[4]) : 0.1;
    const int w = image.width, h = image.height;
    std::vector<double> absolute, diff(size_t(w) * h, 0.0);
    double meanY = 0.0, absRgb = 0.0, sumA = 0.0, sumB = 0.0, squares = 0.0;
    for (size_t i = 0; i < diff.size(); ++i) {
        const float* a = &image.rgba[4 * i];
        const float* b = &reference.rgba[4 * i];
        diff[i] = luminance(a) - luminance(b);
        if (b[3] > minAlpha) {
            absolute.push_back(std::abs(diff[i]));
            meanY += luminance(b);
            for (int c = 0; c < 3; ++c) {
                absRgb += std::abs(double(a[c]) - double(b[c]));
                squares += (double(a[c]) - double(b[c])) * (double(a[c]) - double(b[c]));
                sumA += a[c];
                sumB += b[c];
            }
        }
    }
    if (absolute.empty()) {
        std::fprintf(stderr, "no pixel of the reference has alpha above %g\n", minAlpha);
        return 1;
    }
    meanY /= double(absolute.size());
    std::sort(absolute.begin(), absolute.end());
    double mean = 0.0;
    for (double r : absolute) mean += r;
    mean /= double(absolute.size());
    const double p99 = absolute[size_t(0.99 * double(absolute.size() - 1))];
    const double power = bandPower(diff, w, h, 2.0, 3.0 * pixelsPerVoxel);
    const double rmse = std::sqrt(squares / (3.0 * double(absolute.size()))) /
                        (sumB / (3.0 * double(absolute.size())));
    std::printf("pixels %zu (mean Y %.4f)  |dY|: mean %.5f p99 %.5f  relative RGB: difference %.4f "
                "bias %+.4f rmse %.4f  band power (2 px to 3 voxels) %.3e\n",
                absolute.size(), meanY, mean, p99, absRgb / sumB, sumA / sumB - 1.0, rmse, power);
    return 0;
}
