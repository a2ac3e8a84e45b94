// Writing rendered images: OpenEXR (through OpenImageIO) and PNG previews.
#pragma once

#include <volmorph/render/Camera.h>
#include <volmorph/render/Renderer.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace volmorph::render {

struct ExrOptions {
    bool halfFloat = true;                       ///< half colours (default) or float
    std::map<std::string, std::string> metadata; ///< extra string attributes
    int frame = 0;
    int samples = 0;          ///< the settings' samples (the cap under a noise target)
    double noiseTarget = 0.0; ///< written as volmorph:noiseTarget when above 0
    double renderSeconds = 0.0;
};

/// Writes `image` as an OpenEXR file: RGBA, and its layers when it has them (Renderer.h, layer::),
/// named as Nuke reads them: volume.R/G/B/A, direct.*, indirect.*, emission.* (R, G, B),
/// shadow.A and depth.Z, colours in half (or float) and depth always float. ZIP compression,
/// linear Rec.709 chromaticities, software and version, frame, worldToCamera and worldToNDC,
/// samples and render time, the estimated noise (volmorph:noise, the image's when estimated) and
/// the mean samples per pixel (volmorph:meanSamples). The file appears at
/// `path` only when complete (written under a temporary name, then renamed). Throws
/// std::runtime_error with the reason when it cannot be written.
void writeExr(const Image& image, const Camera& camera, const std::filesystem::path& path,
              const ExrOptions& options);

/// Writes an 8-bit sRGB PNG preview (clamped, over black), atomically like writeExr.
void writePng(const Image& image, const std::filesystem::path& path);

/// Every channel of an image file (its first subimage) as floats.
struct ChannelImage {
    int width = 0, height = 0;
    std::vector<std::string> names; ///< the channels' names, in the file's order
    std::vector<float> values;      ///< names.size() floats per pixel, row-major, top row first

    /// The index of channel `name`, -1 when the file has none.
    int channel(const std::string& name) const;
};

/// Reads every channel of an image through OpenImageIO. Throws std::runtime_error with the reason
/// when it cannot.
ChannelImage readChannels(const std::filesystem::path& path);

/// Reads an image's RGBA pixels (by channel name, else its first four channels), and the layers
/// when the file has them all (tests, diff). Throws std::runtime_error when it cannot.
Image readImage(const std::filesystem::path& path);

} // namespace volmorph::render
