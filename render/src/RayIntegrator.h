// One camera ray's integral through the volume: emission, absorption and single scattering toward
// every light, with the optical depth of each step exact (Cell.h) and the source term taken
// linearly between knots (Renderer.h states the approximation). The renderer's three levels, as
// pbrt-v4 has them: the tile loop and a pixel's samples (Renderer.cpp), and here what happens along
// one ray.
#pragma once

#include <volmorph/render/Camera.h>
#include <volmorph/render/Props.h>
#include <volmorph/render/Renderer.h>

#include "Cell.h"
#include "GridReaders.h"
#include "Majorants.h"
#include "Sampling.h"
#include "Shadows.h"
#include "Sky.h"

#include <limits>
#include <memory>
#include <vector>

namespace volmorph::render {

/// What every ray of one image reads and nothing writes: built once per image.
struct FrameInputs {
    const openvdb::FloatGrid& density;
    const openvdb::Vec3SGrid* color; ///< may be null: white
    const std::vector<Light>& lights;
    const Medium& medium;
    bool levelSet;
    double sigmaPerVoxel; ///< extinction per index unit at density 1
    double stepVoxels;    ///< longest step of the scattering integral
    const PaddedLeaves& padded;
    const Intersector& master;
    const std::vector<Shadow>& shadows;
    // Path tracing (PathTracer.h); unused by the single-scattering estimator.
    const Majorants* majorants; ///< null unless paths are traced
    int bounces;                ///< scattering events after the first (RenderSettings::bounces)
    Sky sky;                    ///< the environment lights
    const Props* props;         ///< may be null: none
};

/// The far end of a ray that meets no prop (world units).
inline constexpr double kNoProp = std::numeric_limits<double>::max();
/// RaySample::depth where the ray meets neither a prop nor alpha 0.5.
inline constexpr double kNoHit = std::numeric_limits<double>::infinity();

/// A piece of a camera ray inside one cell (or constant run), with the optical depth before it.
struct TracedPiece {
    Cell cell;
    double ta, tb, tauBefore;
};

/// One thread's readers of the frame's grids (accessors keep per-thread caches).
struct ThreadReaders {
    const FrameInputs& in;
    Intersector inter;
    DensityReader density;
    Intersector shadowInter;     ///< exact transmittance toward lights (shadowCacheVoxels 0)
    DensityReader shadowDensity; ///< the same
    std::unique_ptr<ColorReader> colors;
    std::vector<Vec3d> perRay;                      ///< per light: scratch for one ray
    std::unique_ptr<Majorants::Accessor> majorants; ///< when paths are traced
    std::vector<TracedPiece> pieces;                ///< scratch for one camera ray

    explicit ThreadReaders(const FrameInputs& frame);
};

/// The unit world direction from world point p toward `light` (directional or point); `distance`
/// gets the world distance to it, 1e30 (beyond any grid) for a directional light.
Vec3d towardLight(const Light& light, const Vec3d& p, double& distance);

/// What reaches world point p from `distance` world units along unit world direction w (kNoProp:
/// from infinitely far): 0 when a prop is in the way, else the volume's exact transmittance, cell
/// by cell (Cell.h). Read by props' direct light, a sky map's light on props and catchers, and the
/// single-scattering estimator without shadow maps.
double exactVisibility(ThreadReaders& readers, const Vec3d& p, const Vec3d& w, double distance);

/// Light `l`'s (directional or point) colour times intensity, over the squared distance for a point
/// light, times the phase function at index point ip from the light toward -direction (unit).
Vec3d lightPhased(const FrameInputs& in, size_t l, const Vec3d& ip, const Vec3d& direction);

/// What light `l` (directional or point) brings to index point ip for a path travelling along
/// `direction` (unit): `phased` gets lightPhased, or `*directional` when given for a directional
/// light (constant along a ray); returns the transmittance toward the light, from its shadow map
/// or cache, or marched exactly when it has none.
double lightArriving(ThreadReaders& readers, size_t l, const Vec3d& ip, const Vec3d& direction,
                     const Vec3d* directional, Vec3d& phased);

/// Radiance (linear RGB, premultiplied) split as the layers split it (Renderer.h, layer::).
struct Radiance {
    Vec3d direct{0.0}, indirect{0.0}, emission{0.0};

    Vec3d sum() const { return direct + indirect + emission; }
    Radiance& operator*=(double s)
    {
        direct *= s;
        indirect *= s;
        emission *= s;
        return *this;
    }
};

/// What one camera ray brings: its radiance and transmittance T, and what the layers take apart.
struct RaySample {
    Radiance L;
    double T = 1.0;
    Vec3d volumeL{0.0};    ///< the volume's radiance in front of the first prop
    double volumeT = 1.0;  ///< the volume's transmittance in front of the first prop
    double shadow = 0.0;   ///< a shadow catcher's matte times volumeT
    double depth = kNoHit; ///< world distance along the ray: alpha passes 0.5, or the prop
};

/// Integrates one world-space camera ray through the frame's volume, up to the first prop, and
/// what that prop adds (PropShading.h); `random` (may be null) draws soft suns' directions there.
RaySample integrateRay(ThreadReaders& readers, const Ray& ray, Random* random = nullptr);

} // namespace volmorph::render
