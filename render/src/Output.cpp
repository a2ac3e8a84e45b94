#include <volmorph/render/Output.h>

#include <volmorph/core/AtomicFile.h>
#include <volmorph/core/Version.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <stdexcept>

namespace volmorph::render {
namespace {

OIIO::ImageSpec specOf(const Image& image, OIIO::TypeDesc type)
{
    OIIO::ImageSpec spec(image.width, image.height, 4, type);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.alpha_channel = 3;
    return spec;
}

void writeWith(const std::filesystem::path& path, const OIIO::ImageSpec& spec, const Image& image)
{
    // Created from the final name (format from its extension), written under a temporary one.
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out)
        throw std::runtime_error("no image writer for " + path.string() + ": " + OIIO::geterror());
    writeAtomically(path, [&](const std::filesystem::path& temporary) {
        bool ok = out->open(temporary.string(), spec);
        ok = ok && out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
        ok = out->close() && ok;
        if (!ok) throw std::runtime_error(out->geterror());
    });
}

OIIO::TypeDesc matrixType()
{
    return OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::MATRIX44);
}

void setMatrix(OIIO::ImageSpec& spec, const char* name, const Mat4d& m)
{
    // OpenEXR stores matrices for row vectors (p' = p M): the transpose of our column form.
    float v[16];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) v[4 * i + j] = float(m(j, i));
    spec.attribute(name, matrixType(), v);
}

} // namespace

void writeExr(const Image& image, const Camera& camera, const std::filesystem::path& path,
              const ExrOptions& options)
{
    OIIO::ImageSpec spec =
        specOf(image, options.halfFloat ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    spec.attribute("Software", std::string("volmorph ") + versionString());
    spec.attribute("volmorph:frame", options.frame);
    spec.attribute("volmorph:samples", options.samples);
    spec.attribute("volmorph:renderSeconds", float(options.renderSeconds));
    // Linear Rec.709 primaries and D65 white: R, G, B, white as (x, y).
    const float chromaticities[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
    spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), chromaticities);
    setMatrix(spec, "worldToCamera", camera.worldToCamera());
    setMatrix(spec, "worldToNDC", camera.worldToNdc());
    for (const auto& [key, value] : options.metadata) spec.attribute(key, value);
    writeWith(path, spec, image);
}

void writePng(const Image& image, const std::filesystem::path& path)
{
    OIIO::ImageBuf linear(specOf(image, OIIO::TypeDesc::FLOAT),
                          const_cast<float*>(image.pixels.data()));
    OIIO::ImageBuf srgb = OIIO::ImageBufAlgo::colorconvert(linear, "linear", "sRGB");
    OIIO::ImageBuf clamped = OIIO::ImageBufAlgo::clamp(srgb, 0.0f, 1.0f);
    writeAtomically(path, [&clamped](const std::filesystem::path& temporary) {
        if (!clamped.write(temporary.string(), OIIO::TypeDesc::UINT8))
            throw std::runtime_error(clamped.geterror());
    });
}

Image readImage(const std::filesystem::path& path)
{
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw std::runtime_error(OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Image image;
    image.width = spec.width;
    image.height = spec.height;
    image.pixels.assign(size_t(spec.width) * size_t(spec.height) * 4, 0.0f);
    std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error(in->geterror());
    for (size_t p = 0; p < size_t(spec.width) * size_t(spec.height); ++p)
        for (int c = 0; c < std::min(4, spec.nchannels); ++c)
            image.pixels[4 * p + size_t(c)] = all[p * size_t(spec.nchannels) + size_t(c)];
    return image;
}

} // namespace volmorph::render
