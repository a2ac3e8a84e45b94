// A volume input's grids resampled onto the scene's transform, and the parts it lacks derived
// (VolumeInput.h).
#include <volmorph/VolumeInput.h>

#include "volume/VolumeFile.h"

#include <volmorph/core/MemoryLimit.h>
#include <volmorph/Voxelize.h>

#include <openvdb/tools/Diagnostics.h>
#include <openvdb/tools/GridTransformer.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/ValueTransformer.h>

#include <cstdio>

namespace volmorph {
namespace {

using openvdb::FloatGrid;
using openvdb::GridBase;
using openvdb::Vec3SGrid;

/// The narrow band of a level set resampled or derived here, voxels on each side (as voxelize()).
constexpr float kHalfWidthVoxels = 3.0f;
/// The density ramp of a level set's fog, voxels (as voxelize()).
constexpr float kRampVoxels = 1.5f;
/// Bytes per output voxel of a float grid while it is resampled (value, mask, the tools'
/// temporaries); a vec3 grid takes three times this.
constexpr double kBytesPerVoxel = 12.0;

/// Throws naming the grid when it holds a NaN or an infinity (voxels, tiles or background).
template <typename GridT>
void checkFinite(const GridT& grid, const detail::VolumeFile& file)
{
    openvdb::tools::Diagnose<GridT> diagnose(grid);
    const openvdb::tools::CheckFinite<GridT, typename GridT::ValueAllCIter> finite;
    if (!diagnose.check(finite).empty())
        throw file.error("grid '" + grid.getName() + "' has " +
                         std::to_string(diagnose.failureCount()) +
                         " non-finite values (NaN or infinity)");
}

/// Reads `name` as GridT (its type was checked when it was picked) and checks its values.
template <typename GridT>
typename GridT::Ptr readChecked(const detail::VolumeFile& file, const std::string& name)
{
    typename GridT::Ptr g = openvdb::gridPtrCast<GridT>(file.read(name));
    if (!g) throw file.error("grid '" + name + "' is not a " + GridT::gridType() + " grid");
    checkFinite(*g, file);
    return g;
}

/// `in` on `xform`: resampled (rebuilt, for a level set), or the grid itself when it is already
/// there.
template <typename GridT>
typename GridT::Ptr resampled(const GridT& in, const openvdb::math::Transform::Ptr& xform,
                              Interrupter* interrupter)
{
    using Value = typename GridT::ValueType;
    const bool levelSet = in.getGridClass() == openvdb::GRID_LEVEL_SET;
    typename GridT::Ptr out = GridT::create(
        levelSet ? Value(kHalfWidthVoxels * float(xform->voxelSize()[0])) : in.background());
    out->setTransform(xform);
    out->setGridClass(in.getGridClass());
    out->setName(in.getName());
    if (in.transform() == *xform) {
        out->setTree(in.tree().copy());
        return out;
    }
    openvdb::util::NullInterrupter none;
    openvdb::util::NullInterrupter& stop = interrupter ? *interrupter : none;
    if (levelSet) { // rebuilt as a level set: a distance field after any scale or rotation
        openvdb::tools::resampleToMatch<openvdb::tools::BoxSampler>(in, *out, stop);
    } else {
        // What resampleToMatch does for other grids, on one thread: OpenVDB's resampler maps each
        // input leaf's box (widened by the sampler's radius) stepping from its corner, so the
        // voxels near a leaf's faces are made by two boxes, a rounding apart, and with threads the
        // one kept depends on their order (20 of cloud-to-bunny's 120,294 cloud voxels, 1 ulp,
        // differed run to run at 2 threads). One thread keeps the same bits at any thread count.
        const openvdb::tools::ABTransform xf(in.transform(), out->transform());
        if (xf.isAffine()) {
            openvdb::tools::GridTransformer transformer(
                xf.getA().baseMap()->getAffineMap()->getMat4() *
                xf.getB().baseMap()->getAffineMap()->getMat4().inverse());
            transformer.setThreaded(false);
            transformer.setInterrupter(stop);
            transformer.transformGrid<openvdb::tools::BoxSampler>(in, *out);
        } else {
            openvdb::tools::GridResampler resampler;
            resampler.setThreaded(false);
            resampler.setInterrupter(stop);
            resampler.transformGrid<openvdb::tools::BoxSampler>(xf, in, *out);
        }
    }
    if (interrupter && interrupter->stopRequested()) throw Interrupted();
    openvdb::tools::prune(out->tree());
    return out;
}

/// The level set of a fog at kFogSurfaceDensity, on `xform`.
FloatGrid::Ptr levelSetOfFog(const FloatGrid& fog, const openvdb::math::Transform::Ptr& xform,
                             Interrupter* interrupter)
{
    // levelSetRebuild takes values below the isovalue as inside: negate the fog.
    FloatGrid::Ptr negated = fog.deepCopy();
    openvdb::tools::foreach (negated->beginValueAll(),
                             [](const FloatGrid::ValueAllIter& it) { it.setValue(-*it); });
    negated->tree().root().setBackground(-fog.background(), /*updateChildNodes=*/false);
    FloatGrid::Ptr sdf =
        openvdb::tools::levelSetRebuild(*negated, -kFogSurfaceDensity, kHalfWidthVoxels,
                                        kHalfWidthVoxels, xform.get(), interrupter);
    if (interrupter && interrupter->stopRequested()) throw Interrupted();
    return sdf;
}

/// Refuses a resampling whose output would not fit under the memory limit.
void checkBudget(const detail::VolumeFile& file, const VolumeInputOptions& o)
{
    const VolumeFileInfo& i = file.info();
    const Vec3d extent = i.empty ? Vec3d(0.0) : i.worldMax - i.worldMin;
    const double voxels = extent.x() * extent.y() * extent.z() / std::pow(o.voxelSize, 3.0);
    const double grids = 2.0 + double(i.extras.size()) + (i.color.empty() ? 0.0 : 3.0);
    const double bytes = voxels * kBytesPerVoxel * grids;
    const uint64_t limit = o.memoryLimitBytes ? o.memoryLimitBytes : defaultMemoryLimitBytes();
    if (bytes <= double(limit)) return;
    char text[300];
    std::snprintf(text, sizeof text,
                  "resampled onto voxel size %g its grids could need %.1f GiB, over the memory "
                  "limit of %.1f GiB; use a larger voxel size or raise the memory limit",
                  o.voxelSize, bytes / double(1ull << 30), double(limit) / double(1ull << 30));
    const Diagnostic d = file.error(text).diagnostics().front();
    throw MemoryLimitExceeded(d.where, d.message, uint64_t(bytes), limit);
}

} // namespace

VolumeInput::VolumeInput(const VolumeSource& source)
    : mFile(std::make_unique<detail::VolumeFile>(source))
{
}

VolumeInput::~VolumeInput() = default;
VolumeInput::VolumeInput(VolumeInput&&) noexcept = default;

const VolumeFileInfo& VolumeInput::info() const
{
    return mFile->info();
}

VolumeFileInfo inspectVolume(const VolumeSource& source)
{
    return VolumeInput(source).info();
}

VolumeSet VolumeInput::resample(const VolumeInputOptions& options, Interrupter* interrupter) const
{
    const detail::VolumeFile& file = *mFile;
    const VolumeSource& source = file.source();
    const VolumeFileInfo& info = file.info();
    checkBudget(file, options);
    if (interrupter) interrupter->start("read volume");
    const openvdb::math::Transform::Ptr xform =
        openvdb::math::Transform::createLinearTransform(options.voxelSize);
    VolumeSet out;
    if (!info.sdf.empty()) {
        FloatGrid::Ptr sdf = readChecked<FloatGrid>(file, info.sdf);
        sdf->setGridClass(openvdb::GRID_LEVEL_SET);
        out.sdf = resampled(*sdf, xform, interrupter);
    }
    if (!info.density.empty()) {
        FloatGrid::Ptr fog = readChecked<FloatGrid>(file, info.density);
        fog->setGridClass(openvdb::GRID_FOG_VOLUME);
        out.density = resampled(*fog, xform, interrupter);
        if (!out.sdf && options.needSdf) out.sdf = levelSetOfFog(*fog, xform, interrupter);
    } else {
        out.density = fogFromLevelSet(*out.sdf, kRampVoxels * float(options.voxelSize));
    }
    if (!info.color.empty())
        out.color = resampled(*readChecked<Vec3SGrid>(file, info.color), xform, interrupter);
    else
        out.color = Vec3SGrid::create(source.color ? Vec3f(*source.color) : Vec3f(0.8f));
    for (const std::string& name : info.extras) {
        const GridBase::Ptr g = file.read(name);
        if (auto f = openvdb::gridPtrCast<FloatGrid>(g)) {
            checkFinite(*f, file);
            out.extras[name] = resampled(*f, xform, interrupter);
        } else if (auto v = openvdb::gridPtrCast<Vec3SGrid>(g)) {
            checkFinite(*v, file);
            out.extras[name] = resampled(*v, xform, interrupter);
        }
    }
    for (const GridBase::Ptr& g :
         {GridBase::Ptr(out.sdf), GridBase::Ptr(out.density), GridBase::Ptr(out.color)})
        if (g) g->setTransform(xform);
    if (out.sdf) out.sdf->setName(kSdfGridName);
    out.density->setName(kDensityGridName);
    out.color->setName(kColorGridName);
    if (interrupter) interrupter->end();
    return out;
}

} // namespace volmorph
