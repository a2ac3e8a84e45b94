#include <volmorph/render/Props.h>

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace volmorph::render {

/// Embree's device and committed scene; one triangle geometry per prop, its id the prop's index.
struct Props::Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;

    ~Embree()
    {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

namespace {

RTCRay embreeRay(const Vec3d& origin, const Vec3d& direction, double tNear, double tFar)
{
    RTCRay ray;
    ray.org_x = float(origin.x());
    ray.org_y = float(origin.y());
    ray.org_z = float(origin.z());
    ray.dir_x = float(direction.x());
    ray.dir_y = float(direction.y());
    ray.dir_z = float(direction.z());
    ray.tnear = float(tNear);
    ray.tfar = tFar >= double(std::numeric_limits<float>::max())
                   ? std::numeric_limits<float>::infinity()
                   : float(tFar);
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    return ray;
}

/// Adds one prop's triangles to `scene` as geometry `id`.
void addMesh(RTCDevice device, RTCScene scene, const PropMesh& mesh, unsigned id)
{
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.points.size()));
    for (size_t i = 0; i < mesh.points.size(); ++i)
        for (int k = 0; k < 3; ++k) vertices[3 * i + size_t(k)] = mesh.points[i][k];
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
        for (int k = 0; k < 3; ++k) indices[3 * i + size_t(k)] = mesh.triangles[i][k];
    rtcCommitGeometry(geometry);
    rtcAttachGeometryByID(scene, geometry, id);
    rtcReleaseGeometry(geometry);
}

/// The per-vertex attribute `values` interpolated at barycentric (u, v) of triangle `tri`.
Vec3d interpolate(const std::vector<Vec3f>& values, const Vec3I& tri, double u, double v)
{
    return Vec3d(values[tri[0]]) * (1.0 - u - v) + Vec3d(values[tri[1]]) * u +
           Vec3d(values[tri[2]]) * v;
}

void checkSizes(const PropMesh& mesh)
{
    for (const std::vector<Vec3f>* values : {&mesh.colors, &mesh.normals, &mesh.velocities})
        if (!values->empty() && values->size() != mesh.points.size())
            throw std::invalid_argument("Props: a per-vertex attribute's size is not the points'");
}

} // namespace

Props::Props(std::vector<PropMesh> meshes) : mMeshes(std::move(meshes))
{
    for (const PropMesh& mesh : mMeshes) checkSizes(mesh);
    mEmbree = std::make_unique<Embree>();
    mEmbree->device = rtcNewDevice(nullptr);
    if (!mEmbree->device)
        throw std::runtime_error("Embree could not start (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    mEmbree->scene = rtcNewScene(mEmbree->device);
    // Robust: no ray slips between two triangles that share an edge.
    rtcSetSceneFlags(mEmbree->scene, RTC_SCENE_FLAG_ROBUST);
    for (size_t i = 0; i < mMeshes.size(); ++i)
        addMesh(mEmbree->device, mEmbree->scene, mMeshes[i], unsigned(i));
    rtcCommitScene(mEmbree->scene);
}

Props::~Props() = default;

bool Props::moves() const
{
    for (const PropMesh& mesh : mMeshes)
        for (const Vec3f& v : mesh.velocities)
            if (v != Vec3f(0.0f)) return true;
    return false;
}

std::unique_ptr<const Props> Props::moved(double seconds) const
{
    std::vector<PropMesh> meshes = mMeshes;
    for (PropMesh& mesh : meshes)
        for (size_t i = 0; i < mesh.velocities.size(); ++i)
            mesh.points[i] = Vec3f(Vec3d(mesh.points[i]) + Vec3d(mesh.velocities[i]) * seconds);
    return std::make_unique<const Props>(std::move(meshes));
}

bool Props::intersect(const Vec3d& origin, const Vec3d& direction, double tNear, double tFar,
                      PropHit& hit) const
{
    if (mMeshes.empty()) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rayHit;
    rayHit.ray = embreeRay(origin, direction, tNear, tFar);
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayHit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mEmbree->scene, &context, &rayHit);
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.distance = double(rayHit.ray.tfar);
    hit.prop = rayHit.hit.geomID;
    Vec3d n(rayHit.hit.Ng_x, rayHit.hit.Ng_y, rayHit.hit.Ng_z);
    const double length = n.length();
    n = length > 0.0 ? n / length : -direction;
    hit.normal = n.dot(direction) > 0.0 ? -n : n;
    const PropMesh& mesh = mMeshes[hit.prop];
    const Vec3I& tri = mesh.triangles[rayHit.hit.primID];
    const double u = rayHit.hit.u, v = rayHit.hit.v;
    hit.shading = hit.normal;
    if (!mesh.normals.empty()) {
        Vec3d s = interpolate(mesh.normals, tri, u, v);
        const double sLength = s.length();
        if (sLength > 0.0) {
            s /= sLength;
            hit.shading = s.dot(hit.normal) < 0.0 ? -s : s;
        }
    }
    hit.reflectance = mesh.colors.empty() ? mesh.color : interpolate(mesh.colors, tri, u, v);
    return true;
}

bool Props::occluded(const Vec3d& origin, const Vec3d& direction, double tNear, double tFar) const
{
    if (mMeshes.empty()) return false;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = embreeRay(origin, direction, tNear, tFar);
    rtcOccluded1(mEmbree->scene, &context, &ray);
    return ray.tfar < 0.0f; // Embree marks an occluded ray with tfar = -inf
}

} // namespace volmorph::render
