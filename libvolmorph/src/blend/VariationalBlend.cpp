#include "blend/VariationalBlend.h"

#include "blend/ExtendedDistance.h"
#include "blend/BlendTime.h"
#include "blend/Redistance.h"
#include "blend/variational/Constraints.h"
#include "blend/variational/PartitionOfUnity.h"
#include "blend/variational/Slice.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/MemoryLimit.h>
#include <volmorph/Schedule.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace volmorph::detail {
namespace {

using openvdb::Coord;
using openvdb::CoordBBox;
using variational::Constraint;
using variational::Interpolant;
using variational::PartitionOfUnity;
using variational::Point4;
using variational::SliceFunction;
using Sampler = openvdb::tools::BoxSampler;

/// The frame's exact values lie on a lattice this many voxels apart, tricubic between: within
/// 0.01 voxel of the exact slice near its zero set (Slice.h).
constexpr int kStride = 2;
/// The partition of unity's coarse level is read from lattices (tricubic between their nodes):
/// its centres at least kSmoothReach steps of 8 voxels (along w = t * time_scale) from the frame
/// from a lattice 8 voxels apart, those at least that many steps of 4 voxels from one 4 voxels
/// apart, and the nearer ones exactly. The centres lie at the shapes' times, and each r^3 is smooth
/// in the slice at the scale of its distance delta along w, but only C2 at its own time (read from
/// a lattice at t = 0, the dino's IoU fell from 0.988 to 0.903). Against the coarse level taken
/// exactly, on dino-to-eight-variational at 256 across, the slice's largest difference within 4
/// voxels of its zero set with every centre delta away: 0.41 voxel at delta = 1.6 steps, 0.17 at
/// 2.4, 0.058 at 3.9, 0.022 at 7.9 (means 0.047, 0.028, 0.011, 0.004; BENCHMARKS.md).
constexpr double kSmoothReach = 3.5;
/// Exterior constraints per edge of the box (kExterior^3 - (kExterior - 2)^3 on its faces).
constexpr int kExterior = 9;
/// |grad f| is taken no smaller than this (world units of f per world unit) in the velocity: where
/// the topology changes the zero set's normal speed has no bound.
constexpr double kLeastGradient = 0.05;
/// A reach along w that takes in every centre (splitByTime's "near" part is then the whole).
constexpr double kEverywhere = std::numeric_limits<double>::infinity();

struct Shape {
    const VolumeSet* volume;
    double t;
};

/// The index-space box of the shapes' narrow bands together.
CoordBBox bandBox(const std::vector<Shape>& shapes)
{
    CoordBBox box;
    for (const Shape& s : shapes) box.expand(s.volume->sdf->evalActiveVoxelBoundingBox());
    return box;
}

/// Exterior constraints (an extension: Turk and O'Brien place none): points on the faces of `box`
/// (index space) at w, each with minus its distance to the shape (world units), so that f stays
/// negative, outside, all around the shapes and the zero set never reaches the box (without them
/// f turned positive far from the dino of dino-to-eight at 128 voxels across, and the frame's
/// inside leaked to the whole world).
std::vector<Constraint> exteriorConstraints(const CoordBBox& box,
                                            const openvdb::math::Transform& transform,
                                            const ExtendedDistance& distance, double w)
{
    ExtendedDistance::Reader<Sampler> d(distance);
    std::vector<Constraint> out;
    const openvdb::Vec3d lo = box.min().asVec3d(), size = (box.max() - box.min()).asVec3d();
    for (int i = 0; i < kExterior; ++i)
        for (int j = 0; j < kExterior; ++j)
            for (int k = 0; k < kExterior; ++k) {
                const auto edge = [](int n) { return n == 0 || n == kExterior - 1; };
                if (!edge(i) && !edge(j) && !edge(k)) continue;
                const openvdb::Vec3d p =
                    lo + size * openvdb::Vec3d(i, j, k) / double(kExterior - 1);
                const openvdb::Vec3d x = transform.indexToWorld(p);
                out.push_back({Point4(x.x(), x.y(), x.z(), w), -double(d(p))});
            }
    return out;
}

UserError variationalError(const VariationalSpec& spec, const std::string& message)
{
    return UserError(spec.where.line > 0 ? spec.where : SourceLocation{"variational"}, message);
}

/// Refuses a solve whose estimated memory exceeds what the limit leaves.
void checkMemory(const VariationalSpec& spec, size_t shapes, uint64_t limit)
{
    const size_t count = variational::kConstraintsPerPoint * size_t(spec.constraints) * shapes;
    const uint64_t need = PartitionOfUnity::estimateBytes(count), resident = residentBytes();
    if (resident + need <= limit) return;
    const auto gib = [](uint64_t b) { return double(b) / double(1ull << 30); };
    char text[400];
    std::snprintf(text, sizeof text,
                  "variational.constraints: %d per shape (%zu constraints over %zu shapes) need "
                  "about %.2f GiB to solve, over the memory limit of %.2f GiB (%.2f GiB in use); "
                  "lower variational.constraints or raise the memory limit",
                  spec.constraints, count, shapes, gib(need), gib(limit), gib(resident));
    throw MemoryLimitExceeded(spec.where.line > 0 ? spec.where : SourceLocation{"variational"},
                              text, resident + need, limit);
}

/// f read at each place's own local time: g(x) = f(x, scale tau(x, t)), and as its rate dg/dw
/// along the frame's w = t * scale, f_w d tau / d t (0 where tau is clamped); the zero set of g is
/// the in-between, and -g_t grad g / |grad g|^2 its normal motion, grad g taking grad tau in.
SliceFunction atLocalTime(SliceFunction f, const LocalTime& local, double t, double scale)
{
    return [f = std::move(f), &local, t, scale](const Point4& p, double* rate) {
        const LocalTau tau = local.at(Vec3d(p[0], p[1], p[2]), t);
        const double value = f(Point4(p[0], p[1], p[2], scale * tau.tau), rate);
        if (rate) *rate *= tau.dt;
        return value;
    };
}

class VariationalBlend final : public TwoSidedBlend {
public:
    explicit VariationalBlend(const BlendSetup& setup) : TwoSidedBlend(setup)
    {
        std::vector<Shape> shapes{{&mSource, 0.0}, {&mTarget, 1.0}};
        if (setup.influences)
            for (const TimedVolume& i : *setup.influences) shapes.push_back({&i.volume, i.t});
        for (const Shape& s : shapes)
            if (!s.volume->sdf)
                throw std::invalid_argument("variational blending needs an sdf grid per shape");
        const VariationalSpec& spec = mSpec.variational;
        mVoxel = mSource.voxelSize();
        mWidth = std::min(mSource.sdf->background(), mTarget.sdf->background());
        const CoordBBox shapesBox = bandBox(shapes);
        const Coord dim = shapesBox.dim();
        mTimeScale = spec.timeScale.value_or(kVariationalTimeScale * mVoxel *
                                             double(std::max({dim.x(), dim.y(), dim.z()})));
        checkMemory(spec, shapes.size(), setup.memoryLimitBytes);
        // The in-betweens lie near the shapes' box: a margin of an eighth, at least 8 voxels.
        const Coord margin(8 + dim.x() / 8, 8 + dim.y() / 8, 8 + dim.z() / 8);
        mBox = CoordBBox(shapesBox.min() - margin, shapesBox.max() + margin);
        tbb::parallel_invoke(
            [&] { mFarSource = ExtendedDistance::make(mSource.sdf, mBox, setup.interrupter); },
            [&] { mFarTarget = ExtendedDistance::make(mTarget.sdf, mBox, setup.interrupter); });
        const openvdb::math::Transform& xform = mSource.density->transform();
        std::vector<Constraint> constraints = exteriorConstraints(mBox, xform, *mFarSource, 0.0);
        const std::vector<Constraint> far =
            exteriorConstraints(mBox, xform, *mFarTarget, mTimeScale);
        constraints.insert(constraints.end(), far.begin(), far.end());
        variational::PartitionOptions options;
        options.leading = constraints.size();
        const std::vector<Constraint> shapeConstraints = sample(shapes);
        constraints.insert(constraints.end(), shapeConstraints.begin(), shapeConstraints.end());
        solve(constraints, options, setup.interrupter);
    }

    BlendedFrame frame(const BlendRequest& r, OutputLeaves& leaves) const override
    {
        const bool velocity = r.velocityScale > 0.0;
        // The coarse level's centres far from the frame's time read from lattices; the nearest
        // ones and the balls' level exact. Under a timing each place is the slice at its own
        // local time, which has kinks where a place starts or ends (tau clamped): every part is
        // taken exactly there (read from a lattice 8 voxels apart across a kink, the top of a
        // swept sphere moved by 0.2 voxel).
        const double w = r.t * mTimeScale, step = kSmoothReach * mVoxel;
        const LocalTime* local = r.localTime && r.localTime->active() ? r.localTime : nullptr;
        const auto [near, rest] = mFunction.coarse().splitByTime(w, local ? kEverywhere : 4 * step);
        const auto [middle, far] = rest.splitByTime(w, 8 * step);
        const auto part = [](const Interpolant& i) {
            return [&i](const Point4& p, double* rate) { return i.evaluateWithRate(p, rate); };
        };
        variational::SplitFunction f{{}, nullptr};
        if (!local) f.smooth.push_back({part(far), 8});
        if (middle.size() > 0) f.smooth.push_back({part(middle), 4});
        SliceFunction detail = [this, &near = near, &far = far, local](const Point4& p,
                                                                       double* rate) {
            double nearRate = 0.0, farRate = 0.0;
            double value = near.evaluateWithRate(p, rate ? &nearRate : nullptr) +
                           mFunction.evaluateLocal(p, rate);
            if (local) value += far.evaluateWithRate(p, rate ? &farRate : nullptr); // polynomial
            if (rate) *rate += nearRate + farRate;
            return value;
        };
        f.detail = local ? atLocalTime(std::move(detail), *local, r.t, mTimeScale) : detail;
        variational::NearZeroSlice slice =
            variational::sliceNearZero(f, w, mSource.density->transformPtr(), mBox, kStride,
                                       mWidth / mVoxel + 1.0, velocity, r.interrupter);
        std::vector<std::unique_ptr<openvdb::Vec3STree::LeafNodeType>> velocities;
        if (velocity) velocities = normalMotion(slice, r.velocityScale / mVoxel);
        std::vector<OutputLeaves::ValueLeaf*> values;
        slice.values->tree().stealNodes(values);
        for (size_t i = 0; i < values.size(); ++i) {
            ExtraLeaves extras;
            if (velocity) extras.velocity = std::move(velocities[i]);
            leaves.keep(std::unique_ptr<OutputLeaves::ValueLeaf>(values[i]),
                        leaves.make(values[i]->origin(), 0.0f).second, std::move(extras));
        }
        return assemble(r, leaves, velocity, slice.evaluations);
    }

private:
    /// Each shape's constraints at its time.
    std::vector<Constraint> sample(const std::vector<Shape>& shapes) const
    {
        const VariationalSpec& spec = mSpec.variational;
        std::vector<Constraint> all;
        for (const Shape& s : shapes) {
            try {
                const std::vector<Constraint> c = variational::sampleConstraints(
                    *s.volume->sdf, size_t(spec.constraints), spec.normalOffsetVoxels * mVoxel,
                    s.t * mTimeScale);
                all.insert(all.end(), c.begin(), c.end());
            } catch (const std::invalid_argument& e) {
                throw variationalError(spec,
                                       "the shape at t = " + std::to_string(s.t) + ": " + e.what());
            }
        }
        return all;
    }

    void solve(const std::vector<Constraint>& constraints,
               const variational::PartitionOptions& options, Interrupter* interrupter)
    {
        try {
            mFunction = PartitionOfUnity::solve(constraints, options, interrupter);
        } catch (const std::invalid_argument& e) {
            throw variationalError(mSpec.variational, e.what());
        }
    }

    /// The zero set's normal motion, -f_t grad f / |grad f|^2, at the slice's voxels, in world
    /// units per second (`perSecond`: world units per second of one world unit per unit t); one
    /// leaf per leaf of the slice's values, in their order.
    std::vector<std::unique_ptr<openvdb::Vec3STree::LeafNodeType>>
    normalMotion(const variational::NearZeroSlice& slice, double perSecond) const
    {
        using VelocityLeaf = openvdb::Vec3STree::LeafNodeType;
        openvdb::tree::LeafManager<const openvdb::FloatTree> manager(slice.values->tree());
        std::vector<std::unique_ptr<VelocityLeaf>> out(manager.leafCount());
        const double inv2dx = 0.5 / mVoxel;
        manager.foreach ([&](const OutputLeaves::ValueLeaf& leaf, size_t n) {
            auto b = slice.values->getConstAccessor();
            auto rates = slice.rates->getConstAccessor();
            auto v = std::make_unique<VelocityLeaf>(leaf.origin(), openvdb::Vec3s(0.0f), false);
            for (auto it = leaf.cbeginValueOn(); it; ++it) {
                const Coord c = it.getCoord();
                const openvdb::Vec3d g(
                    b.getValue(c.offsetBy(1, 0, 0)) - b.getValue(c.offsetBy(-1, 0, 0)),
                    b.getValue(c.offsetBy(0, 1, 0)) - b.getValue(c.offsetBy(0, -1, 0)),
                    b.getValue(c.offsetBy(0, 0, 1)) - b.getValue(c.offsetBy(0, 0, -1)));
                const openvdb::Vec3d grad = g * inv2dx;
                const double ft = double(rates.getValue(c)) * mTimeScale; // per unit t
                const double norm2 = std::max(grad.lengthSqr(), kLeastGradient * kLeastGradient);
                v->setValueOn(it.pos(), openvdb::Vec3s(grad * (-ft * perSecond / norm2)));
            }
            out[n] = std::move(v);
        });
        return out;
    }

    /// The grids from the kept leaves: the interior by sign, the band rebuilt as distances with
    /// its fog, colour on the band, the velocity cut to the band.
    BlendedFrame assemble(const BlendRequest& r, OutputLeaves& leaves, bool velocity,
                          size_t evaluations) const
    {
        BlendedFrame out;
        openvdb::FloatGrid::Ptr values = openvdb::FloatGrid::create(mWidth);
        values->setTransform(mSource.density->transform().copy());
        values->setGridClass(openvdb::GRID_LEVEL_SET);
        out.grids.color = openvdb::Vec3SGrid::create(leaves.background());
        openvdb::Vec3SGrid::Ptr motion = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        ExtraTrees trees;
        if (velocity) trees.velocity = &motion->tree();
        out.keptLeaves = leaves.size();
        leaves.moveInto(values->tree(), out.grids.color->tree(), -mWidth, trees);
        openvdb::tools::signedFloodFill(values->tree());
        const RedistanceBands bands{float(mVoxel), mWidth,
                                    [](const Coord&) { return std::numeric_limits<float>::max(); }};
        out.grids.density = redistance(*values, bands, kSdfRampVoxels * float(mVoxel));
        colorBand(*values, BlendTime(mSpec.color, r.t, r.localTime, values->transform()),
                  *out.grids.color);
        if (velocity) {
            motion->tree().topologyIntersection(values->tree());
            out.grids.velocity = motion;
        }
        out.grids.sdf = values;
        out.blendSamples = evaluations;
        return out;
    }

    /// Each side's colour at its surface point nearest the voxel (p - d grad d / |grad d| on its
    /// extended distance), mixed by the colour schedule at each voxel's tau, at the band's voxels.
    void colorBand(const openvdb::FloatGrid& sdf, const BlendTime& tauColor,
                   openvdb::Vec3SGrid& color) const
    {
        openvdb::tree::LeafManager<openvdb::Vec3STree> manager(color.tree());
        manager.foreach ([&](openvdb::Vec3STree::LeafNodeType& leaf, size_t) {
            const auto* band = sdf.tree().probeConstLeaf(leaf.origin());
            if (!band) {
                leaf.setValuesOff();
                return;
            }
            ExtendedDistance::Reader<Sampler> readS(*mFarSource), readT(*mFarTarget);
            LeafDistances dS(readS, leaf.origin()), dT(readT, leaf.origin());
            auto cS = mSource.color->getConstAccessor();
            auto cT = mTarget.color->getConstAccessor();
            leaf.setValueMask(band->getValueMask());
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const Coord c = it.getCoord();
                const openvdb::Vec3s s = Sampler::sample(cS, nearestSurfacePoint(dS, c));
                const openvdb::Vec3s t = Sampler::sample(cT, nearestSurfacePoint(dT, c));
                it.setValue(s + tauColor.at(c).tau * (t - s));
            }
        });
    }

    /// One side's distances at the voxels of a leaf and one voxel around it, each read once
    /// (a voxel's central differences share their reads with its neighbours').
    class LeafDistances {
    public:
        LeafDistances(ExtendedDistance::Reader<Sampler>& read, const Coord& origin)
            : mRead(read), mLo(origin - Coord(1))
        {
            mValues.fill(std::numeric_limits<float>::quiet_NaN());
        }
        float operator()(const Coord& c)
        {
            const Coord u = c - mLo;
            float& v = mValues[size_t((u.x() * kSide + u.y()) * kSide + u.z())];
            if (std::isnan(v)) v = mRead(c.asVec3d());
            return v;
        }

    private:
        static constexpr int kSide = 10; // a leaf's 8 and one on each side
        ExtendedDistance::Reader<Sampler>& mRead;
        Coord mLo;
        std::array<float, kSide * kSide * kSide> mValues;
    };

    /// c - d grad d / |grad d| (index space), grad d by central differences.
    openvdb::Vec3R nearestSurfacePoint(LeafDistances& d, const Coord& c) const
    {
        const openvdb::Vec3R g(d(c.offsetBy(1, 0, 0)) - d(c.offsetBy(-1, 0, 0)),
                               d(c.offsetBy(0, 1, 0)) - d(c.offsetBy(0, -1, 0)),
                               d(c.offsetBy(0, 0, 1)) - d(c.offsetBy(0, 0, -1)));
        const double length = g.length();
        if (length < 1e-9) return c.asVec3d();
        return c.asVec3d() - g * (double(d(c)) / mVoxel / length);
    }

    double mVoxel = 1.0, mTimeScale = 1.0;
    float mWidth = 0.0f;
    CoordBBox mBox; ///< where the in-betweens are looked for (index space)
    PartitionOfUnity mFunction;
    std::unique_ptr<const ExtendedDistance> mFarSource, mFarTarget;
};

} // namespace

std::unique_ptr<const BlendMethod> makeVariationalBlend(const BlendSetup& setup)
{
    return std::make_unique<VariationalBlend>(setup);
}

} // namespace volmorph::detail
