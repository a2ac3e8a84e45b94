// The scene parser's table groups, one unit each (SceneParser.cpp is the root). Each reads its
// tables into the Scene's settings and reports problems through the Reader, never throwing.
#pragma once

#include <volmorph/Scene.h>

#include "TomlReader.h"

#include <toml++/toml.h>

#include <filesystem>
#include <string>
#include <vector>

namespace volmorph::detail {

inline constexpr double kDegreesToRadians = 3.14159265358979323846 / 180.0;

/// [source] and [target]: mesh (resolved against `folder`), transform, color; `extraKeys` are
/// the caller's own keys in the same table (an influence shape's t).
void parseObject(Reader& r, const toml::node& node, const std::string& path,
                 const std::filesystem::path& folder, ObjectSpec& object,
                 const std::vector<std::string>& extraKeys = {});
/// [[prop]]: meshes in the shot (mesh, transform, color, holdout, shadow_catcher).
void parseProps(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                std::vector<PropSpec>& props);
/// [volume]: voxel_size or resolution.
void parseVolume(Reader& r, const toml::node& node, VolumeSpec& volume);
/// [[pair]]: appends every pair that is complete.
void parsePairs(Reader& r, const toml::node& node, std::vector<FeaturePairSpec>& pairs);
/// [warp] and [blend] (with its schedules).
void parseWarp(Reader& r, const toml::node& node, WarpSpec& warp);
void parseBlend(Reader& r, const toml::node& node, BlendSpec& blend);
/// [variational], its influence shapes' files resolved against `folder`.
void parseVariational(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                      VariationalSpec& variational, std::vector<InfluenceSpec>& influences);
/// [surface] (surface mode): correspondence, interpolation, kernel.
void parseSurface(Reader& r, const toml::node& node, SurfaceSpec& surface);
/// [timing] (spread, sweep) and its [[timing.region]]s, their files resolved against `folder`.
void parseTiming(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                 TimingSettings& timing, std::vector<TimingRegionSpec>& regions);
/// [render], its camera and lights (with their keys); a sky map's path resolved against `folder`.
void parseRender(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                 RenderSpec& render);
/// A file name at `n`, resolved against `folder`, that must exist: into `file`, and where it was
/// written into `where`.
void parseFile(Reader& r, const toml::node& n, const std::string& path,
               const std::filesystem::path& folder, std::filesystem::path& file,
               SourceLocation& where);

} // namespace volmorph::detail
