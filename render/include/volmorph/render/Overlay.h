// Drawing on rendered images, for previews: world-space lines projected through the camera, point
// markers, text labels, and contact sheets of several frames. Colours are linear RGB; drawn pixels
// are opaque (alpha 1, premultiplied like the film).
#pragma once

#include <volmorph/render/Camera.h>
#include <volmorph/render/Renderer.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace volmorph::render {

using Color = std::array<float, 3>;

/// The image position (pixels, as Camera::ray) of world point p, or nothing when p is not in front
/// of the camera.
std::optional<std::array<double, 2>> project(const Camera& camera, const Vec3d& p);

/// Draws the world-space segment a-b, clipped to the part in front of the camera and to the image,
/// `thickness` pixels wide.
void drawSegment(Image& image, const Camera& camera, const Vec3d& a, const Vec3d& b,
                 const Color& color, int thickness = 2);

/// Draws a screen-space marker (a square with a cross) of `radius` pixels around world point p.
void drawMarker(Image& image, const Camera& camera, const Vec3d& p, const Color& color,
                int radius = 5);

/// Draws `text` with its baseline starting at pixel (x, y) through OpenImageIO's render_text (font
/// DejaVu Sans). Returns false, drawing nothing, when no font can be loaded.
bool drawText(Image& image, int x, int y, const std::string& text, const Color& color,
              int sizePixels = 16);

/// Composites `image` over an opaque background colour (so empty space shows as that colour).
Image overBackground(const Image& image, const Color& background);

/// A grid of `tiles` (all the same size), `columns` across, each scaled to `tileWidth` pixels wide,
/// with its label written below it, over `background`. Gaps of a few pixels separate the tiles.
Image contactSheet(const std::vector<Image>& tiles, const std::vector<std::string>& labels,
                   int columns, int tileWidth, const Color& background);

} // namespace volmorph::render
