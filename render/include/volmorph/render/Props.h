// Props: meshes placed in the shot beside the volume, intersected with Embree. A diffuse prop
// occludes the volume, receives its shadow and casts its own onto it; a holdout cuts the alpha of
// whatever lies behind it and renders nothing itself; a shadow catcher is transparent but for the
// shadow it receives, which it shows as a matte, A = 1 - received / unoccluded irradiance, RGB 0
// (as Cycles' shadow catcher). Every prop, whatever its role, blocks light toward what lies behind
// it. A prop may carry per-vertex reflectance (colours), shading normals (interpolated across each
// triangle: smooth shading) and velocities (it moves under motion blur: renderMotionBlurred builds
// it again at each shutter time, each vertex moved linearly along its velocity); one that stands
// still is built once for a sequence. A `subject` prop is what the shot is of (a surface morph's
// in-between): it goes into the Volume layer as the volume would.
#pragma once

#include <volmorph/core/Math.h>

#include <memory>
#include <vector>

namespace volmorph::render {

struct PropMesh {
    enum class Role { Diffuse, Holdout, ShadowCatcher };
    std::vector<Vec3f> points; ///< world units
    std::vector<Vec3I> triangles;
    Vec3d color{0.8, 0.8, 0.8}; ///< diffuse reflectance, linear RGB in [0, 1]
    Role role = Role::Diffuse;
    /// Optional, one per point each (empty: none): the reflectance per vertex (linear RGB in
    /// [0, 1], interpolated, replacing `color`), the shading normal per vertex (interpolated; it
    /// need not be unit length), the velocity per vertex (world units per second).
    std::vector<Vec3f> colors, normals, velocities;
    bool subject = false; ///< in the Volume layer, as the volume is (Renderer.h, layer::kVolume)
};

/// A ray's first prop: its distance (world units along a unit direction), the prop, the unit
/// geometric normal there, turned to face the ray's origin, the unit shading normal (the
/// interpolated vertex normal on the same side; the geometric one without normals), and the
/// reflectance there.
struct PropHit {
    double distance = 0.0;
    size_t prop = 0;
    Vec3d normal{0.0, 0.0, 1.0};
    Vec3d shading{0.0, 0.0, 1.0};
    Vec3d reflectance{0.8, 0.8, 0.8};
};

class Props {
public:
    /// Builds Embree's scene of `meshes` (which are copied). Throws std::runtime_error when Embree
    /// cannot start.
    explicit Props(std::vector<PropMesh> meshes);
    ~Props();
    Props(const Props&) = delete;
    Props& operator=(const Props&) = delete;

    bool empty() const { return mMeshes.empty(); }
    /// Whether a prop has a non-zero velocity.
    bool moves() const;
    /// The props `seconds` from now: each point moved by its velocity times `seconds`.
    std::unique_ptr<const Props> moved(double seconds) const;
    const PropMesh& mesh(size_t i) const { return mMeshes[i]; }

    /// The first prop along origin + t direction (unit) for tNear < t < tFar; false when none.
    bool intersect(const Vec3d& origin, const Vec3d& direction, double tNear, double tFar,
                   PropHit& hit) const;
    /// Whether any prop lies along origin + t direction (unit) for tNear < t < tFar.
    bool occluded(const Vec3d& origin, const Vec3d& direction, double tNear, double tFar) const;

private:
    struct Embree;
    std::vector<PropMesh> mMeshes;
    std::unique_ptr<Embree> mEmbree;
};

} // namespace volmorph::render
