// The scene: a validated, in-memory description of one morph sequence, parsed from a TOML file
// that users write by hand. Every key, its unit and its default is documented in scenes/README.md.
//
// Units: lengths are world units unless a name says Voxels; angles are degrees in the file and
// radians in code (only Camera::fovDegrees keeps degrees, as vdb_render's flag does, and says so).
#pragma once

#include <volmorph/BlendSettings.h>
#include <volmorph/SurfaceSettings.h>
#include <volmorph/TimingSettings.h>
#include <volmorph/FeaturePair.h>
#include <volmorph/VolumeSource.h>
#include <volmorph/WarpSettings.h>
#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>
#include <volmorph/core/ObjectTransform.h>

#include <openvdb/math/Mat4.h>
#include <openvdb/math/Vec3.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace volmorph {

/// One side of the morph: a mesh file or a volume file, and how it is placed.
struct ObjectSpec {
    std::filesystem::path mesh;    ///< resolved against the scene file's folder; empty for a volume
    std::filesystem::path volume;  ///< a .vdb (fog or level set), resolved; empty for a mesh. A
                                   ///< sequence is a pattern (fx.####.vdb): see volumeAt()
    std::vector<int> volumeFrames; ///< a sequence's frame numbers found on disk, sorted
    SourceLocation fileWhere;      ///< where `mesh` or `volume` was written, for errors on reading
    VolumeGridNames grids;         ///< volume only
    /// NIfTI only: the intensities [lo, hi] mapped to density 0..1 (clamped); unset: the file's
    /// cal_min..cal_max, else its data's range.
    std::optional<std::pair<double, double>> window;
    ObjectTransform transform;  ///< applied after the volume's own transform
    std::optional<Vec3d> color; ///< linear RGB; when absent, the mesh's vertex colours or grey
                                ///< (a volume's colour grid, or grey)

    bool isVolume() const { return !volume.empty(); }
    bool isSequence() const { return !volumeFrames.empty(); }
    const std::filesystem::path& file() const { return isVolume() ? volume : mesh; }
    /// A sequence's file for output frame `frame`: the input frame of the same number, or the
    /// nearest before it on disk (held), the first before the sequence starts. Not a sequence:
    /// `volume`.
    std::filesystem::path volumeAt(int frame) const;
    /// The volume stage's input for a single volume file (`volume` as it is: a sequence's pattern
    /// is resolved first, by volumeAt or sceneAtFrame).
    VolumeSource volumeSource() const;
};

/// An extra shape the variational function passes through at time t, steering the in-betweens
/// near t toward it (Turk and O'Brien's intermediate shapes).
struct InfluenceSpec {
    ObjectSpec object; ///< a mesh or a single volume file (no sequence), placed as a side is
    double t = 0.5;    ///< in (0, 1)
};

/// A [[timing.region]]: a closed mesh or a fog mask (density 0.5 its surface) inside which the
/// morph starts at `start` (in t), fading into the rest's delay over `softness` world units
/// outside.
struct TimingRegionSpec {
    ObjectSpec shape; ///< a mesh or a single volume file, placed as a side is
    double start = 0.0;
    double softness = 0.0;
    SourceLocation where; ///< the region's table
};

/// A [[prop]]: a mesh in the shot beside the morph, seen and lit by the renderer only.
struct PropSpec {
    std::filesystem::path mesh; ///< resolved against the scene file's folder
    SourceLocation where;       ///< where `mesh` was written, for errors on reading
    ObjectTransform transform;
    Vec3d color{0.8, 0.8, 0.8}; ///< diffuse reflectance, linear RGB in [0, 1]
    bool holdout = false;       ///< cuts the volume's alpha behind it, renders nothing
    bool shadowCatcher = false; ///< shows only the shadow it receives, as a matte
};

/// Voxel grid settings: exactly one of voxelSize and resolution is set by the file.
struct VolumeSpec {
    std::optional<double> voxelSize; ///< world units
    std::optional<int> resolution;   ///< voxels across the longest side of the larger object
};

enum class Projection { Perspective, Orthographic };

/// The camera at one key frame: every value, those the key leaves out copied from the camera.
struct CameraKey {
    int frame = 0;
    Vec3d eye, lookat, up;
    double fovDegrees = 40.0, orthoWidth = 2.0;
};

struct CameraSpec {
    Projection projection = Projection::Perspective;
    Vec3d eye{0.0, 0.0, 5.0};
    Vec3d lookat{0.0, 0.0, 0.0};
    Vec3d up{0.0, 1.0, 0.0};
    double fovDegrees = 40.0;    ///< horizontal, perspective only
    double orthoWidth = 2.0;     ///< world units, orthographic only
    std::vector<CameraKey> keys; ///< animation, by increasing frame; empty: still (the CLI's
                                 ///< KeyframeTrack interpolates them)
};

enum class LightType { Directional, Point, Environment };

/// A light at one key frame: every value, those the key leaves out copied from the light.
struct LightKey {
    int frame = 0;
    Vec3d direction, position, color;
    double intensity = 1.0;
};

struct LightSpec {
    LightType type = LightType::Directional;
    Vec3d direction{0.0, -1.0, 0.0}; ///< directional: the way light travels (unit length)
    Vec3d position{0.0, 0.0, 0.0};   ///< point: world units
    Vec3d color{1.0, 1.0, 1.0};
    double intensity = 1.0;
    double angleRadians = 0.0; ///< directional: angular diameter (a soft sun); the file has degrees
    /// Environment: a lat-long HDR image (resolved against the scene file's folder) whose radiance,
    /// times color x intensity, arrives from each direction; empty: a constant sky.
    std::filesystem::path map;
    SourceLocation mapWhere;    ///< where `map` was written, for errors on reading
    std::vector<LightKey> keys; ///< animation, by increasing frame; empty: still (the CLI's
                                ///< KeyframeTrack interpolates them)
};

struct RenderSpec {
    int width = 960, height = 540; ///< pixels
    int samples = 4;               ///< per pixel: exactly, or the cap under a noise target
    /// The noise target: the frame's estimated relative RMSE against its converged image, at which
    /// the renderer stops (adaptive sampling up to `samples`); 0: exactly `samples` samples.
    double noise = 0.0;
    bool denoise = true;           ///< under a noise target, denoise the frame (render.denoise)
    double stepVoxels = 0.5;       ///< ray-march step
    double extinction = 40.0;      ///< per world unit at density 1
    double albedo = 0.8;           ///< single-scattering albedo, 0..1
    double anisotropy = 0.0;       ///< Henyey-Greenstein g, -1 < g < 1
    Vec3d emission{0.0, 0.0, 0.0}; ///< radiance emitted per unit optical depth, linear RGB
    /// Volume scattering events after the first, as Cycles' volume bounces: 0 (the default, the
    /// fast path) is single scattering; more trace paths (multiple scattering).
    int bounces = 0;
    /// Spacing of the transmittance caches toward lights, in voxels; 0: exact per sample.
    int shadowCacheVoxels = 1;
    /// The EXR's layers for compositing beside RGBA (volume, direct, indirect, emission, shadow,
    /// depth.Z).
    bool layers = true;
    unsigned seed = 0;
    /// Motion blur: the shutter's open and close, in frames around the frame ([-0.25, 0.25]: half a
    /// frame centred on it); open == close (the default) renders the instant.
    std::pair<double, double> shutter{0.0, 0.0};
    bool motionBlur() const { return shutter.second > shutter.first; }
    CameraSpec camera;
    std::vector<LightSpec> lights; ///< default: one directional light from above-front
};

/// The frames of the sequence. Frame f has t = (f - first) / (last - first); a single-frame
/// range has t = 0. Picking frames on the command line never changes their t.
struct FramesSpec {
    int first = 1, last = 1;
    std::string output = "out/frame.####.exr"; ///< relative to the scene folder; #### or %04d pads
    SourceLocation outputWhere;
    double fps = 24.0; ///< frames per second: what a frame is in time (velocity in world units per
                       ///< second, motion blur's shutter)

    int count() const { return last - first + 1; }
    double t(int frame) const;
    /// The seconds one unit of t lasts: (last - first) / fps; 0 for a single frame (t stands
    /// still).
    double secondsPerUnitT() const { return last > first ? double(last - first) / fps : 0.0; }
};

struct Scene {
    std::filesystem::path file;   ///< the scene file as given
    std::filesystem::path folder; ///< paths in the file are relative to this
    ObjectSpec source, target;
    VolumeSpec volume;
    std::vector<FeaturePairSpec> pairs;
    WarpSpec warp;
    BlendSpec blend;
    std::vector<InfluenceSpec> influences; ///< [variational] influence (variational mode only)
    SurfaceSpec surface;                   ///< [surface] (surface mode only)
    TimingSettings timing;                 ///< [timing]: where the morph happens when
    std::vector<TimingRegionSpec> timingRegions; ///< [[timing.region]]
    RenderSpec render;
    std::vector<PropSpec> props;
    FramesSpec frames;
};

/// The scene with each volume sequence replaced by its file for output frame `frame`
/// (ObjectSpec::volumeAt).
Scene sceneAtFrame(const Scene& scene, int frame);

/// Reads, parses and validates a scene file. Throws UserError listing every problem found, each
/// with file:line:col; checks that mesh files exist (it does not import them).
Scene loadScene(const std::filesystem::path& file);

/// Parses scene text; `file` names it in diagnostics and anchors relative paths.
Scene parseScene(std::string_view text, const std::filesystem::path& file);

/// Parses a frame range "FIRST-LAST" or "N" (negative frame numbers allowed, as "-5--1").
/// Returns false when the text is not such a range or FIRST > LAST.
bool parseFrameRange(std::string_view text, int& first, int& last);

} // namespace volmorph
