// How far a frame is from the converged image, when the converged image is itself two renders of
// the brute-force path tracer with different seeds (issue 56's reference): their mean is the
// reference, their difference measures its own noise, which is taken out of the frame's error in
// quadrature. Over the pixels both references cover (alpha above 0.1), RGB:
// - rmse: the frame's relative RMSE against the converged image (its mean square error minus the
//   reference's own noise, square-rooted, over the reference's mean), and the raw figure;
// - bias: sum frame / sum reference - 1;
// - p99: the 99th percentile of the per-pixel relative error of luminance, |Y - Yref| / Yref over
//   pixels whose Yref exceeds a tenth of the mean (the reference's own noise included);
// - the frame's own estimate (EXR metadata volmorph:noise) and its mean samples per pixel.
// usage: volmorph_bench_noise_error FRAME.exr REFERENCE1.exr REFERENCE2.exr
#include <OpenImageIO/imagebuf.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Frame {
    int width = 0, height = 0;
    std::vector<float> rgba;
    float noise = NAN, meanSamples = NAN;
};

bool load(const std::string& path, Frame& frame)
{
    OIIO::ImageBuf buf(path);
    if (!buf.read(0, 0, true, OIIO::TypeDesc::FLOAT) || buf.nchannels() < 4) {
        std::fprintf(stderr, "%s: cannot read an RGBA image\n", path.c_str());
        return false;
    }
    frame.width = buf.spec().width;
    frame.height = buf.spec().height;
    frame.rgba.resize(size_t(frame.width) * frame.height * 4);
    buf.get_pixels(OIIO::ROI(0, frame.width, 0, frame.height, 0, 1, 0, 4), OIIO::TypeDesc::FLOAT,
                   frame.rgba.data());
    frame.noise = buf.spec().get_float_attribute("volmorph:noise", NAN);
    frame.meanSamples = buf.spec().get_float_attribute("volmorph:meanSamples", NAN);
    return true;
}

double luminance(const float* p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 4) {
        std::fprintf(stderr, "usage: %s FRAME.exr REFERENCE1.exr REFERENCE2.exr\n", argv[0]);
        return 2;
    }
    Frame f, r1, r2;
    if (!load(argv[1], f) || !load(argv[2], r1) || !load(argv[3], r2)) return 1;
    if (f.rgba.size() != r1.rgba.size() || f.rgba.size() != r2.rgba.size()) {
        std::fprintf(stderr, "the images differ in size\n");
        return 1;
    }
    double frameSquares = 0.0, refSquares = 0.0, sumF = 0.0, sumR = 0.0, meanY = 0.0;
    size_t covered = 0;
    std::vector<size_t> pixels;
    for (size_t p = 0; p < f.rgba.size() / 4; ++p) {
        const float *a = &f.rgba[4 * p], *b1 = &r1.rgba[4 * p], *b2 = &r2.rgba[4 * p];
        if (!(b1[3] > 0.1f && b2[3] > 0.1f)) continue;
        ++covered;
        pixels.push_back(p);
        for (int c = 0; c < 3; ++c) {
            const double ref = 0.5 * (double(b1[c]) + b2[c]);
            frameSquares += (a[c] - ref) * (a[c] - ref);
            refSquares += (double(b1[c]) - b2[c]) * (double(b1[c]) - b2[c]);
            sumF += a[c];
            sumR += ref;
        }
        meanY += 0.5 * (luminance(b1) + luminance(b2));
    }
    if (covered == 0) {
        std::fprintf(stderr, "no pixel covered by the references\n");
        return 1;
    }
    const double n = 3.0 * double(covered), mean = sumR / n;
    // Each reference's variance is refSquares / n / 2; their mean's, half that.
    const double refVariance = refSquares / n / 4.0, raw = frameSquares / n;
    const double rmse = std::sqrt(std::max(0.0, raw - refVariance)) / mean;
    meanY /= double(covered);
    std::vector<double> relative;
    for (size_t p : pixels) {
        const double y = 0.5 * (luminance(&r1.rgba[4 * p]) + luminance(&r2.rgba[4 * p]));
        if (y > 0.1 * meanY) relative.push_back(std::abs(luminance(&f.rgba[4 * p]) - y) / y);
    }
    std::sort(relative.begin(), relative.end());
    const double p99 =
        relative.empty() ? NAN : relative[size_t(0.99 * double(relative.size() - 1))];
    std::printf("rmse %.4f (raw %.4f, reference's own %.4f) bias %+.4f p99 %.4f estimate %.4f "
                "samples %.1f pixels %zu\n",
                rmse, std::sqrt(raw) / mean, std::sqrt(refVariance) / mean, sumF / sumR - 1.0, p99,
                double(f.noise), double(f.meanSamples), covered);
    return 0;
}
