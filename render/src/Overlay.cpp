#include <volmorph/render/Overlay.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace volmorph::render {
namespace {

/// An ImageBuf over the image's own pixels (no copy): drawing writes into `image`.
OIIO::ImageBuf wrap(Image& image)
{
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.alpha_channel = 3;
    return OIIO::ImageBuf(spec, image.pixels.data());
}

/// Homogeneous clip coordinates of p: (x, y) / w are NDC in [0, 1] across the image.
std::array<double, 4> clip(const Mat4d& worldToNdc, const Vec3d& p)
{
    std::array<double, 4> h{};
    for (int i = 0; i < 4; ++i)
        h[size_t(i)] = worldToNdc(i, 0) * p.x() + worldToNdc(i, 1) * p.y() +
                       worldToNdc(i, 2) * p.z() + worldToNdc(i, 3);
    return h;
}

/// Liang-Barsky: clips the 2D segment to [lo, hi] in both axes; false when nothing is left.
bool clip2d(double& x0, double& y0, double& x1, double& y1, double lo, double hiX, double hiY)
{
    double t0 = 0.0, t1 = 1.0;
    const double dx = x1 - x0, dy = y1 - y0;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {x0 - lo, hiX - x0, y0 - lo, hiY - y0};
    for (int i = 0; i < 4; ++i) {
        if (p[i] == 0.0) {
            if (q[i] < 0.0) return false;
            continue;
        }
        const double r = q[i] / p[i];
        if (p[i] < 0.0)
            t0 = std::max(t0, r);
        else
            t1 = std::min(t1, r);
        if (t0 > t1) return false;
    }
    const double ax = x0 + t0 * dx, ay = y0 + t0 * dy;
    x1 = x0 + t1 * dx;
    y1 = y0 + t1 * dy;
    x0 = ax;
    y0 = ay;
    return true;
}

std::vector<float> rgba(const Color& c)
{
    return {c[0], c[1], c[2], 1.0f};
}

} // namespace

std::optional<std::array<double, 2>> project(const Camera& camera, const Vec3d& p)
{
    const std::array<double, 4> h = clip(camera.worldToNdc(), p);
    if (!(h[3] > 1e-9)) return std::nullopt;
    return std::array<double, 2>{h[0] / h[3] * camera.width(), h[1] / h[3] * camera.height()};
}

void drawSegment(Image& image, const Camera& camera, const Vec3d& a, const Vec3d& b,
                 const Color& color, int thickness)
{
    const Mat4d m = camera.worldToNdc();
    std::array<double, 4> ha = clip(m, a), hb = clip(m, b);
    // Keep the part in front of the camera (w > near), clipping in homogeneous space.
    constexpr double kNear = 1e-6;
    if (ha[3] < kNear && hb[3] < kNear) return;
    if (ha[3] < kNear || hb[3] < kNear) {
        const double s = (kNear - ha[3]) / (hb[3] - ha[3]);
        std::array<double, 4> cut{};
        for (size_t i = 0; i < 4; ++i) cut[i] = ha[i] + s * (hb[i] - ha[i]);
        (ha[3] < kNear ? ha : hb) = cut;
    }
    double x0 = ha[0] / ha[3] * image.width, y0 = ha[1] / ha[3] * image.height;
    double x1 = hb[0] / hb[3] * image.width, y1 = hb[1] / hb[3] * image.height;
    if (!clip2d(x0, y0, x1, y1, 0.0, image.width - 1.0, image.height - 1.0)) return;
    OIIO::ImageBuf buffer = wrap(image);
    const std::vector<float> c = rgba(color);
    for (int dy = 0; dy < std::max(1, thickness); ++dy)
        for (int dx = 0; dx < std::max(1, thickness); ++dx)
            OIIO::ImageBufAlgo::render_line(buffer, int(std::lround(x0)) + dx,
                                            int(std::lround(y0)) + dy, int(std::lround(x1)) + dx,
                                            int(std::lround(y1)) + dy, c);
}

void drawMarker(Image& image, const Camera& camera, const Vec3d& p, const Color& color, int radius)
{
    const auto q = project(camera, p);
    if (!q) return;
    const int x = int(std::lround((*q)[0])), y = int(std::lround((*q)[1]));
    if (x < -radius || y < -radius || x > image.width + radius || y > image.height + radius) return;
    OIIO::ImageBuf buffer = wrap(image);
    const std::vector<float> c = rgba(color);
    OIIO::ImageBufAlgo::render_box(buffer, x - radius, y - radius, x + radius, y + radius, c);
    OIIO::ImageBufAlgo::render_line(buffer, x - radius, y, x + radius, y, c);
    OIIO::ImageBufAlgo::render_line(buffer, x, y - radius, x, y + radius, c);
}

bool drawText(Image& image, int x, int y, const std::string& text, const Color& color,
              int sizePixels)
{
    OIIO::ImageBuf buffer = wrap(image);
    const std::vector<float> c = rgba(color);
    return OIIO::ImageBufAlgo::render_text(buffer, x, y, text, sizePixels, "DejaVuSans", c);
}

Image overBackground(const Image& image, const Color& background)
{
    Image out = image;
    OIIO::ImageBuf front = wrap(out);
    OIIO::ImageBuf back(front.spec());
    OIIO::ImageBufAlgo::fill(back, {background[0], background[1], background[2], 1.0f});
    OIIO::ImageBufAlgo::over(front, front, back); // premultiplied A over B, in place
    return out;
}

Image contactSheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels,
                   int columns, int tileWidth, const Color& background)
{
    if (tiles.empty()) throw std::invalid_argument("contactSheet: no tiles");
    columns = std::max(1, std::min(columns, int(tiles.size())));
    const int rows = (int(tiles.size()) + columns - 1) / columns;
    const int tileHeight =
        std::max(1, int(std::lround(double(tileWidth) * tiles[0].height / tiles[0].width)));
    constexpr int kGap = 6, kLabel = 22;
    Image sheet;
    sheet.width = columns * (tileWidth + kGap) + kGap;
    sheet.height = rows * (tileHeight + kLabel + kGap) + kGap;
    sheet.pixels.assign(size_t(sheet.width) * size_t(sheet.height) * 4, 0.0f);
    sheet = overBackground(sheet, background);
    OIIO::ImageBuf out = wrap(sheet);
    bool labelsDrawn = true;
    for (size_t i = 0; i < tiles.size(); ++i) {
        Image tile = overBackground(tiles[i], background);
        OIIO::ImageBuf source = wrap(tile);
        OIIO::ImageBuf scaled;
        const OIIO::ROI size(0, tileWidth, 0, tileHeight, 0, 1, 0, 4);
        if (!OIIO::ImageBufAlgo::resize(scaled, source, "", 0.0f, size))
            throw std::runtime_error("contact sheet: cannot resize a frame: " + scaled.geterror());
        const int x = kGap + int(i) % columns * (tileWidth + kGap);
        const int y = kGap + int(i) / columns * (tileHeight + kLabel + kGap);
        OIIO::ImageBufAlgo::paste(out, x, y, 0, 0, scaled);
        if (i < labels.size() && labelsDrawn)
            labelsDrawn = OIIO::ImageBufAlgo::render_text(
                out, x + 2, y + tileHeight + 16, labels[i], 14, "DejaVuSans",
                std::vector<float>{0.8f, 0.8f, 0.8f, 1.0f});
    }
    return sheet; // `out` wrote into its pixels
}

} // namespace volmorph::render
