// The blend stage's settings: which method makes the in-between, its schedules, and the
// variational method's parameters. Influence shapes reach the method as volumes
// (MorphOptions::influences), never as files.
#pragma once

#include <volmorph/Schedule.h>
#include <volmorph/core/Diagnostics.h>

#include <map>
#include <optional>
#include <string>

namespace volmorph {

/// Surface: no voxels are blended; the surface stage makes one mesh per frame (SurfaceMorph.h).
enum class BlendMode { Density, Sdf, Variational, Surface };

/// Turk and O'Brien's variational implicit morph (BlendMode::Variational).
struct VariationalSpec {
    int constraints = 5000;          ///< surface points per shape, each with an inward partner
    double normalOffsetVoxels = 1.0; ///< the inward partners' depth, voxels
    /// World units per unit of t (the fourth axis's scale); unset: kVariationalTimeScale times the
    /// longest side of the shapes' bounds together.
    std::optional<double> timeScale;
    SourceLocation
        where; ///< where these settings were written (a scene's [variational]), if anywhere
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

} // namespace volmorph
