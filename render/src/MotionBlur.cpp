// Eulerian motion blur (Renderer.h, renderMotionBlurred): one sub-frame image per shutter time, of
// the volume moved along its velocity by that time (its mean exactly, the rest advected) and the
// props moved along their vertices' velocities, averaged.
#include <volmorph/render/Renderer.h>

#include <volmorph/core/Interrupter.h>

#include <openvdb/tools/ValueTransformer.h>
#include <openvdb/tools/VolumeAdvect.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

namespace volmorph::render {
namespace {

using Advection =
    openvdb::tools::VolumeAdvection<openvdb::Vec3SGrid, false, openvdb::util::NullInterrupter>;

/// The volume's motion split in two: its density-weighted mean velocity, a translation applied
/// exactly (the grids' transforms moved, nothing resampled), and the rest, advected. Each
/// advection resamples the grid (trilinear, adding f(1 - f) voxels^2 of spread at a fractional
/// offset f on top of the renderer's own read), so a volume that translates as a whole blurs
/// without it (exactly, as Cycles reads p - v t), and any other motion resamples only by what
/// differs from the mean (rho(p - v_mean s - r(p - v_mean s) s), r = v - v_mean: first order in s,
/// as the Eulerian read itself).
class Motion {
public:
    Motion(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* velocity,
           openvdb::util::NullInterrupter* interrupter)
    {
        if (!velocity) return;
        Vec3d sum(0.0);
        double weight = 0.0;
        const auto rho = density.getConstAccessor();
        for (auto it = velocity->cbeginValueOn(); it; ++it) { // serial: the same bits every time
            const double w = std::max(0.0f, rho.getValue(it.getCoord()));
            sum += w * Vec3d(*it);
            weight += w;
        }
        if (!(weight > 0.0)) return;
        mMean = sum / weight;
        mRest = velocity->deepCopy();
        const Vec3f mean(mMean);
        openvdb::tools::foreach (
            mRest->beginValueOn(),
            [mean](const openvdb::Vec3SGrid::ValueOnIter& v) { v.setValue(*v - mean); });
        mAdvection.emplace(*mRest, interrupter);
        mAdvection->setIntegrator(openvdb::tools::Scheme::SEMI); // rho(p - r(p) s): Eulerian
        if (!(mAdvection->getMaxVelocity() > 1e-6 * mMean.length())) mAdvection.reset();
    }

    /// The grid at `seconds` from the frame: the input itself where nothing moves, else a grid
    /// (kept in `moved`) advected by the rest and moved by the mean.
    template <typename GridT>
    const GridT* at(const GridT* grid, double seconds, typename GridT::Ptr& moved)
    {
        if (!grid || seconds == 0.0 || (!mAdvection && mMean == Vec3d(0.0))) return grid;
        moved = mAdvection
                    ? mAdvection->template advect<GridT, openvdb::tools::BoxSampler>(*grid, seconds)
                    : openvdb::ConstPtrCast<GridT>(grid->copy()); // the tree shared, not changed
        moved->setTransform(grid->transform().copy());
        moved->transform().postTranslate(mMean * seconds);
        return moved.get();
    }

private:
    Vec3d mMean{0.0}; ///< world units per second
    openvdb::Vec3SGrid::Ptr mRest;
    std::optional<Advection> mAdvection;
};

} // namespace

std::vector<double> shutterOffsets(double open, double close, int samples)
{
    const int n = std::clamp(samples, 1, 64);
    std::vector<double> out;
    for (int k = 0; k < n; ++k) out.push_back(open + (k + 0.5) / n * (close - open));
    return out;
}

Image renderMotionBlurred(const openvdb::FloatGrid& density, const openvdb::Vec3SGrid* color,
                          const openvdb::Vec3SGrid* velocity, const std::vector<ShutterTime>& times,
                          const Medium& medium, const RenderSettings& settings)
{
    if (times.empty()) throw std::invalid_argument("renderMotionBlurred: no shutter time");
    Motion motion(density, velocity, settings.interrupter);
    RenderSettings each = settings;
    each.samples = std::max(1, settings.samples / int(times.size()));
    // The mean of K independent images of noise e each has noise e / sqrt(K).
    each.noise = settings.noise * std::sqrt(double(times.size()));
    Image sum;
    for (size_t k = 0; k < times.size(); ++k) {
        const ShutterTime& time = times[k];
        openvdb::FloatGrid::Ptr movedDensity;
        openvdb::Vec3SGrid::Ptr movedColor;
        const openvdb::FloatGrid* d = motion.at(&density, time.seconds, movedDensity);
        const openvdb::Vec3SGrid* c = motion.at(color, time.seconds, movedColor);
        if (settings.interrupter && settings.interrupter->wasInterrupted()) throw Interrupted();
        std::unique_ptr<const Props> movedProps;
        if (settings.props && settings.props->moves() && time.seconds != 0.0) {
            movedProps = settings.props->moved(time.seconds);
            each.props = movedProps.get();
        } else {
            each.props = settings.props;
        }
        each.seed = shutterSeed(settings.seed, k);
        const Image image = renderVolume(*d, c, time.camera, time.lights, medium, each);
        if (k == 0) {
            sum = image;
        } else {
            for (size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += image.pixels[i];
            for (size_t i = 0; i < sum.variance.size(); ++i) sum.variance[i] += image.variance[i];
            sum.meanSamples += image.meanSamples;
            for (size_t i = 0; i < sum.layers.size(); ++i)
                sum.layers[i] = i % layer::kFloats == layer::kDepth
                                    ? std::min(sum.layers[i], image.layers[i])
                                    : sum.layers[i] + image.layers[i];
        }
    }
    for (float& v : sum.pixels) v /= float(times.size());
    const float k2 = float(times.size()) * float(times.size());
    for (float& v : sum.variance) v /= k2; // var of the mean of K independent images
    sum.noise = estimateNoise(sum);
    for (size_t i = 0; i < sum.layers.size(); ++i)
        if (i % layer::kFloats != layer::kDepth) sum.layers[i] /= float(times.size());
    return sum;
}

} // namespace volmorph::render
