#include <volmorph/render/Output.h>

#include <volmorph/core/AtomicFile.h>
#include <volmorph/core/Version.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace volmorph::render {
namespace {

/// The layers' channel names (Renderer.h, layer::), as Nuke reads an EXR's layers.
constexpr const char* kLayerNames[layer::kFloats] = {
    "volume.R",   "volume.G",   "volume.B",   "volume.A",   "direct.R",
    "direct.G",   "direct.B",   "indirect.R", "indirect.G", "indirect.B",
    "emission.R", "emission.G", "emission.B", "shadow.A",   "depth.Z"};

OIIO::ImageSpec specOf(const Image& image, OIIO::TypeDesc type)
{
    OIIO::ImageSpec spec(image.width, image.height, 4, type);
    spec.channelnames = {"R", "G", "B", "A"};
    spec.alpha_channel = 3;
    return spec;
}

/// RGBA, then the layers if the image has them: colours in `type`, depth as float.
OIIO::ImageSpec exrSpecOf(const Image& image, OIIO::TypeDesc type)
{
    OIIO::ImageSpec spec = specOf(image, type);
    if (image.layers.empty()) return spec;
    spec.nchannels = 4 + layer::kFloats;
    spec.channelformats.assign(size_t(spec.nchannels), type);
    for (const char* name : kLayerNames) spec.channelnames.push_back(name);
    spec.channelformats[4 + layer::kDepth] = OIIO::TypeDesc::FLOAT;
    spec.z_channel = 4 + layer::kDepth;
    return spec;
}

/// The image's channels interleaved as `spec` lists them (RGBA, then the layers).
std::vector<float> interleaved(const OIIO::ImageSpec& spec, const Image& image)
{
    if (spec.nchannels == 4) return image.pixels;
    const size_t pixels = size_t(image.width) * size_t(image.height), n = size_t(spec.nchannels);
    std::vector<float> all(pixels * n);
    for (size_t p = 0; p < pixels; ++p) {
        std::copy_n(&image.pixels[4 * p], 4, &all[n * p]);
        std::copy_n(&image.layers[layer::kFloats * p], layer::kFloats, &all[n * p + 4]);
    }
    return all;
}

void writeWith(const std::filesystem::path& path, const OIIO::ImageSpec& spec, const Image& image)
{
    const std::vector<float> all = interleaved(spec, image);
    // Created from the final name (format from its extension), written under a temporary one.
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out)
        throw std::runtime_error("no image writer for " + path.string() + ": " + OIIO::geterror());
    writeAtomically(path, [&](const std::filesystem::path& temporary) {
        bool ok = out->open(temporary.string(), spec);
        ok = ok && out->write_image(OIIO::TypeDesc::FLOAT, all.data());
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
        exrSpecOf(image, options.halfFloat ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    spec.attribute("Software", std::string("volmorph ") + versionString());
    spec.attribute("volmorph:frame", options.frame);
    spec.attribute("volmorph:samples", options.samples);
    spec.attribute("volmorph:renderSeconds", float(options.renderSeconds));
    // The noise estimate and the mean samples a pixel took (adaptive sampling: fewer than the cap).
    if (std::isfinite(image.noise)) spec.attribute("volmorph:noise", float(image.noise));
    if (options.noiseTarget > 0.0)
        spec.attribute("volmorph:noiseTarget", float(options.noiseTarget));
    if (image.meanSamples > 0.0) spec.attribute("volmorph:meanSamples", float(image.meanSamples));
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

int ChannelImage::channel(const std::string& name) const
{
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : int(it - names.begin());
}

ChannelImage readChannels(const std::filesystem::path& path)
{
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw std::runtime_error(OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    ChannelImage image;
    image.width = spec.width;
    image.height = spec.height;
    image.names = spec.channelnames;
    image.names.resize(size_t(spec.nchannels));
    image.values.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.values.data()))
        throw std::runtime_error(in->geterror());
    return image;
}

Image readImage(const std::filesystem::path& path)
{
    const ChannelImage all = readChannels(path);
    const size_t pixels = size_t(all.width) * size_t(all.height), n = all.names.size();
    Image image;
    image.width = all.width;
    image.height = all.height;
    // RGBA by name (the first four channels where they are not named so); the layers when all
    // are there.
    auto copy = [&](const char* const* names, int count, std::vector<float>& to, bool byPosition) {
        to.assign(pixels * size_t(count), 0.0f);
        for (int c = 0; c < count; ++c) {
            int from = all.channel(names[c]);
            if (from < 0 && byPosition && size_t(c) < n) from = c;
            if (from < 0) continue;
            for (size_t p = 0; p < pixels; ++p)
                to[size_t(count) * p + size_t(c)] = all.values[n * p + size_t(from)];
        }
    };
    const char* const rgba[4] = {"R", "G", "B", "A"};
    copy(rgba, 4, image.pixels, all.channel("R") < 0);
    if (all.channel(kLayerNames[0]) >= 0 && all.channel("depth.Z") >= 0)
        copy(kLayerNames, layer::kFloats, image.layers, false);
    return image;
}

} // namespace volmorph::render
