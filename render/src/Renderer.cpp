// The ray marcher. The only translation unit of render/ with OpenVDB's tools headers.
#include <volmorph/render/Renderer.h>

#include <openvdb/math/Ray.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/RayIntersector.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <limits>

namespace volmorph::render {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::FloatGrid;
using VdbRay = openvdb::math::Ray<double>;
using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::BoolGrid>;

/// Transmittance below this ends a ray: what is behind contributes less than 1e-4.
constexpr double kMinTransmittance = 1e-4;
const double kMaxOpticalDepth = -std::log(kMinTransmittance);

/// A counter-based generator: the same (pixel, sample, frame, seed) always gives the same numbers.
struct Random {
    uint64_t state;
    Random(uint64_t a, uint64_t b, uint64_t c)
    {
        state = mix(a * 0x9E3779B97F4A7C15ull ^ mix(b + 0x632BE59BD9B4E019ull) ^ mix(c + 0x85157AF5ull));
    }
    static uint64_t mix(uint64_t z)
    {
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double next()
    {
        state += 0x9E3779B97F4A7C15ull;
        return double(mix(state) >> 11) * (1.0 / 9007199254740992.0);
    }
};

double henyeyGreenstein(double cosTheta, double g)
{
    const double d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * d * std::sqrt(d));
}

/// Where a trilinear sample of `density` can be non-zero: its active voxels and tiles, dilated by one
/// voxel. (VolumeRayIntersector's own dilation ignores tiles, so a tile on a volume's boundary
/// would lose the half voxel of ramp outside it.)
openvdb::BoolGrid::Ptr rayMask(const FloatGrid& density, bool levelSet)
{
    openvdb::BoolGrid::Ptr mask = openvdb::BoolGrid::create(false);
    mask->setTransform(density.transform().copy());
    mask->tree().topologyUnion(density.tree());
    // A level set's interior is inactive (negative background): add it.
    if (levelSet) mask->tree().topologyUnion(openvdb::tools::sdfInteriorMask(density)->tree());
    openvdb::tools::dilateActiveValues(mask->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::PRESERVE_TILES);
    return mask;
}

/// Density at index position ip: the fog's value, or 1 inside a level set.
template <typename Accessor>
inline float densityAt(const Accessor& acc, const Vec3d& ip, bool levelSet)
{
    const float v = openvdb::tools::BoxSampler::sample(acc, ip);
    return levelSet ? (v < 0.0f ? 1.0f : 0.0f) : v;
}

/// Optical depth from world point p along `direction` for up to `distance` world units.
double opticalDepth(Intersector& inter, bool levelSet, openvdb::tree::ValueAccessor<const openvdb::FloatTree>& acc,
                    const Vec3d& p, const Vec3d& direction, double distance, double sigmaPerVoxel, double step)
{
    if (!inter.setWorldRay(VdbRay(p, direction, 0.0, distance))) return 0.0;
    double tau = 0.0, t0 = 0.0, t1 = 0.0;
    while (inter.march(t0, t1)) {
        for (double t = t0 + 0.5 * step; t < t1; t += step) {
            const float rho = densityAt(acc, inter.getIndexPos(t), levelSet);
            if (rho > 0.0f) tau += sigmaPerVoxel * rho * step;
        }
        if (tau > kMaxOpticalDepth) break;
    }
    return tau;
}

/// Transmittance toward one light, on a coarse grid over the occupied region.
FloatGrid::Ptr transmittanceCache(const FloatGrid& density, const openvdb::BoolGrid& mask, bool levelSet,
                                  const Light& light, double sigmaPerVoxel, const RenderSettings& settings)
{
    const int factor = std::max(1, settings.shadowCacheVoxels);
    const double voxel = density.voxelSize()[0];
    FloatGrid::Ptr cache = FloatGrid::create(1.0f);
    cache->setTransform(openvdb::math::Transform::createLinearTransform(voxel * factor));
    auto coarse = [factor](const Coord& c) {
        auto f = [factor](int v) { return v >= 0 ? v / factor : -((-v + factor - 1) / factor); };
        return Coord(f(c.x()), f(c.y()), f(c.z()));
    };
    for (auto leaf = mask.tree().cbeginLeaf(); leaf; ++leaf) {
        const CoordBBox b = leaf->getNodeBoundingBox();
        cache->tree().fill(CoordBBox(coarse(b.min()), coarse(b.max())), 1.0f, true);
    }
    auto tiles = mask.tree().cbeginValueOn();
    tiles.setMaxDepth(openvdb::BoolTree::ValueOnCIter::LEAF_DEPTH - 1);
    for (; tiles; ++tiles) {
        if (tiles.isVoxelValue()) continue;
        const CoordBBox b = tiles.getBoundingBox();
        cache->tree().fill(CoordBBox(coarse(b.min()), coarse(b.max())), 1.0f, true);
    }
    openvdb::tools::dilateActiveValues(cache->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX, openvdb::tools::IGNORE_TILES);
    cache->tree().voxelizeActiveTiles();

    const Intersector master(mask);
    const double step = settings.shadowStepVoxels;
    const Vec3d travel = light.direction.unit();
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(cache->tree());
    leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, size_t) {
        Intersector inter(master);
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(density.tree());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            const Vec3d p = cache->indexToWorld(it.getCoord());
            Vec3d toward = -travel;
            double distance = std::numeric_limits<double>::max();
            if (light.type == Light::Type::Point) {
                toward = light.position - p;
                distance = toward.length();
                if (distance <= 0.0) continue;
                toward /= distance;
            }
            it.setValue(float(std::exp(-opticalDepth(inter, levelSet, acc, p, toward, distance, sigmaPerVoxel, step))));
        }
    });
    return cache;
}

} // namespace

Image renderVolume(const FloatGrid& density, const openvdb::Vec3SGrid* color, const Camera& camera,
                   const std::vector<Light>& lights, const Medium& medium, const RenderSettings& settings)
{
    Image image;
    image.width = camera.width();
    image.height = camera.height();
    image.pixels.assign(size_t(image.width) * size_t(image.height) * 4, 0.0f);
    const bool levelSet = medium.kind == Medium::Kind::LevelSet;
    if (density.tree().activeVoxelCount() == 0) return image;

    const double voxel = density.voxelSize()[0];
    const double sigmaPerVoxel = medium.extinction * voxel; // per index unit
    const int samples = std::max(1, settings.samples);
    const int strata = int(std::ceil(std::sqrt(double(samples))));
    const double inverseFactor = 1.0 / double(std::max(1, settings.shadowCacheVoxels));

    auto body = [&] {
        const openvdb::BoolGrid::Ptr mask = rayMask(density, levelSet);
        std::vector<FloatGrid::Ptr> caches;
        for (const Light& light : lights)
            caches.push_back(transmittanceCache(density, *mask, levelSet, light, sigmaPerVoxel, settings));
        const Intersector master(*mask);
        tbb::parallel_for(tbb::blocked_range2d<int>(0, image.height, 16, 0, image.width, 16),
                          [&](const tbb::blocked_range2d<int>& tile) {
            Intersector inter(master);
            openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(density.tree());
            std::unique_ptr<openvdb::tree::ValueAccessor<const openvdb::Vec3STree>> colors;
            if (color) colors = std::make_unique<openvdb::tree::ValueAccessor<const openvdb::Vec3STree>>(color->tree());
            std::vector<openvdb::tree::ValueAccessor<const openvdb::FloatTree>> cacheAcc;
            for (const auto& c : caches) cacheAcc.emplace_back(c->tree());
            std::vector<Vec3d> perRay(lights.size());
            for (int y = tile.rows().begin(); y != tile.rows().end(); ++y) {
                for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
                    double r = 0, g = 0, b = 0, alpha = 0;
                    for (int s = 0; s < samples; ++s) {
                        Random random(uint64_t(y) * 65536u + uint64_t(x), uint64_t(s), (uint64_t(settings.frame) << 32) ^ settings.seed);
                        // One sample goes through the pixel centre (no antialiasing, as vdb_render);
                        // more are stratified and jittered over the pixel.
                        const double jx = random.next(), jy = random.next();
                        const double sx = samples == 1 ? 0.5 : ((s % strata) + jx) / strata;
                        const double sy = samples == 1 ? 0.5 : ((s / strata) % strata + jy) / strata;
                        const Ray ray = camera.ray(x + sx, y + sy);
                        const double jitter = random.next();
                        double T = 1.0;
                        Vec3d L(0.0);
                        if (inter.setWorldRay(VdbRay(ray.origin, ray.direction))) {
                            // A directional light's phase and colour are constant along a ray.
                            for (size_t l = 0; l < lights.size(); ++l) {
                                const Light& light = lights[l];
                                perRay[l] = light.color * (light.intensity *
                                    henyeyGreenstein(light.direction.unit().dot(-ray.direction), medium.anisotropy));
                            }
                            const double h = settings.stepVoxels;
                            double t0 = 0, t1 = 0;
                            while (T > kMinTransmittance && inter.march(t0, t1)) {
                                // Samples on one lattice along the whole ray: t_k = (k + jitter) h.
                                for (double t = (std::ceil(t0 / h - jitter) + jitter) * h; t < t1; t += h) {
                                    const Vec3d ip = inter.getIndexPos(t);
                                    const float rho = densityAt(acc, ip, levelSet);
                                    if (!(rho > 0.0f)) continue;
                                    const double transmitted = std::exp(-sigmaPerVoxel * rho * h);
                                    const double absorbed = T * (1.0 - transmitted);
                                    Vec3d albedo(medium.albedo);
                                    if (colors) {
                                        const openvdb::Vec3s c = openvdb::tools::BoxSampler::sample(*colors, ip);
                                        albedo = Vec3d(c.x(), c.y(), c.z()) * medium.albedo;
                                    }
                                    Vec3d source = medium.emission;
                                    // The caches share the density's origin, at `factor` times its voxel.
                                    const Vec3d cacheIndex = ip * inverseFactor;
                                    for (size_t l = 0; l < lights.size(); ++l) {
                                        const Light& light = lights[l];
                                        Vec3d c = perRay[l];
                                        if (light.type == Light::Type::Point) {
                                            Vec3d travel = inter.getWorldPos(t) - light.position;
                                            const double d2 = travel.lengthSqr();
                                            travel /= std::sqrt(d2);
                                            c = light.color * (light.intensity / d2 *
                                                henyeyGreenstein(travel.dot(-ray.direction), medium.anisotropy));
                                        }
                                        const double Tl = openvdb::tools::BoxSampler::sample(cacheAcc[l], cacheIndex);
                                        source += Vec3d(albedo.x() * c.x(), albedo.y() * c.y(), albedo.z() * c.z()) * Tl;
                                    }
                                    L += absorbed * source;
                                    T *= transmitted;
                                    if (T <= kMinTransmittance) break;
                                }
                            }
                        }
                        r += L.x();
                        g += L.y();
                        b += L.z();
                        alpha += 1.0 - T;
                    }
                    float* px = image.at(x, y);
                    px[0] = float(r / samples);
                    px[1] = float(g / samples);
                    px[2] = float(b / samples);
                    px[3] = float(alpha / samples);
                }
            }
        });
    };
    if (settings.threads > 0) tbb::task_arena(settings.threads).execute(body);
    else body();
    return image;
}

} // namespace volmorph::render
