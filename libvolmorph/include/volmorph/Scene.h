// The scene: a validated, in-memory description of one morph sequence, parsed from a TOML file
// that users write by hand. Every key, its unit and its default is documented in scenes/README.md.
//
// Units: lengths are world units unless a name says Voxels; angles are degrees in the file and
// radians in code (only Camera::fovDegrees keeps degrees, as vdb_render's flag does, and says so).
#pragma once

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/Math.h>

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

/// Object-to-world placement of a mesh: scale, then rotate about X, then Y, then Z, then translate.
struct ObjectTransform {
    Vec3d translate{0.0, 0.0, 0.0}; ///< world units
    Vec3d rotateRadians{0.0, 0.0, 0.0};
    Vec3d scale{1.0, 1.0, 1.0}; ///< uniform or per axis; every component > 0

    /// Column-vector convention p' = M p (OpenVDB stores it transposed: use transform() to apply).
    Mat4d matrix() const;
    Vec3d apply(const Vec3d& p) const;
    bool isIdentity() const;
};

/// Which grids of a volume input play which part. An empty name: the first of the defaults
/// (volmorph/VolumeInput.h) that the file holds.
struct VolumeGridNames {
    std::string density, sdf, color;
    SourceLocation where; ///< the `grids` key, for a name the file lacks
};

/// Whether `file` is a NIfTI volume (.nii or .nii.gz), by its name.
bool isNiftiFile(const std::filesystem::path& file);

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

enum class FeatureType { Point, Segment, Rectangle, Box };
const char* toString(FeatureType type);

/// One feature element (Lerios et al. 1995): an origin, an orthonormal frame and scales.
/// The type only chooses the distance function; a segment is scale.x long along xAxis, a rectangle
/// scale.x by scale.y in the xAxis-yAxis plane, a box scale.x by scale.y by scale.z; all centred on
/// origin.
struct FeatureElement {
    Vec3d origin{0.0, 0.0, 0.0}; ///< world units
    Vec3d xAxis{1.0, 0.0, 0.0};  ///< unit length; the frame is orthonormal and right-handed
    Vec3d yAxis{0.0, 1.0, 0.0};
    Vec3d zAxis{0.0, 0.0, 1.0};
    Vec3d scale{1.0, 1.0, 1.0}; ///< world units, every component > 0
};

struct FeaturePairSpec {
    FeatureType type = FeatureType::Point;
    FeatureElement source;
    FeatureElement target;
    SourceLocation where; ///< the [[pair]] header
};

enum class Weighting { InverseSquare, BeierNeely };

struct WarpSpec {
    double epsilon = 0.01;         ///< world units; w = (d + epsilon)^-2
    double toleranceVoxels = 0.25; ///< approximation error bound; 0 = exact warp
    Weighting weighting = Weighting::InverseSquare;
    /// Beier-Neely weights w = (len^p / (a + d))^b, used only with Weighting::BeierNeely.
    double a = 0.01, b = 2.0, p = 0.0;
};

/// tau(t) for one attribute. Points are (t, tau) pairs sorted by t, interpolated linearly.
/// Evaluated by the blend stage (volmorph/Schedule.h).
struct ScheduleSpec {
    enum class Kind { Linear, Smoothstep, Sigmoid, Curve };
    Kind kind = Kind::Linear;
    double k = 8.0; ///< sigmoid steepness
    std::vector<std::pair<double, double>> points;
};

enum class BlendMode { Density, Sdf, Variational };

/// An extra shape the variational function passes through at time t, steering the in-betweens
/// near t toward it (Turk and O'Brien's intermediate shapes).
struct InfluenceSpec {
    ObjectSpec object; ///< a mesh or a single volume file (no sequence), placed as a side is
    double t = 0.5;    ///< in (0, 1)
};

/// [variational]: Turk and O'Brien's variational implicit morph (blend.mode = "variational").
struct VariationalSpec {
    int constraints = 5000;          ///< surface points per shape, each with an inward partner
    double normalOffsetVoxels = 1.0; ///< the inward partners' depth, voxels
    /// World units per unit of t (the fourth axis's scale); unset: kVariationalTimeScale times the
    /// longest side of the shapes' bounds together.
    std::optional<double> timeScale;
    std::vector<InfluenceSpec> influence;
    SourceLocation where; ///< the [variational] table, when given
};

/// The default time scale over the longest side of the shapes' bounds (BENCHMARKS.md: a sphere
/// into itself bulges 1.8% mid-way at a quarter of its diameter, 20% at one diameter; a sphere into
/// one twice its size grows monotonically up to 0.4 of the larger's diameter, not at 0.8).
inline constexpr double kVariationalTimeScale = 0.2;

struct BlendSpec {
    BlendMode mode = BlendMode::Density;
    ScheduleSpec density;
    ScheduleSpec color;
    ScheduleSpec sdf;
    /// sdf mode: pieces of an in-between smaller than this many voxels, apart from its largest
    /// piece, are dropped (dust that a distance blend leaves where the blended field has an
    /// isolated minimum); 0 keeps everything.
    int minIslandVoxels = 27;
    /// Schedules of the other grids volume inputs carry (temperature, flame, ...), by grid name;
    /// a grid not named here follows the density schedule.
    struct GridSchedule {
        ScheduleSpec schedule;
        SourceLocation where;
    };
    std::map<std::string, GridSchedule> grids;
    VariationalSpec variational; ///< variational mode only
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
    int samples = 4;               ///< jittered samples per pixel
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
