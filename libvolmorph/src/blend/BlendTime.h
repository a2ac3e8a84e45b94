// One schedule's tau at each output voxel under the scene's timing (LocalTime.h): the schedule
// applied to the local time tau(x, t), with its derivatives in t and in space (the velocity's chain
// rule). Without a timing every voxel takes the schedule at t, and the gradient is 0.
#pragma once

#include <volmorph/LocalTime.h>
#include <volmorph/Schedule.h>

#include <openvdb/math/Transform.h>

#include <algorithm>
#include <cmath>

namespace volmorph::detail {

/// A schedule's tau at a voxel, d tau / d t there, and grad tau per index unit.
struct VoxelTau {
    float tau = 0.0f;
    float dt = 0.0f;
    Vec3f gradient{0.0f};
};

class BlendTime {
public:
    /// `local` may be null (everywhere at once); `xform`: the output's index-to-world transform.
    BlendTime(const ScheduleSpec& schedule, double t, const LocalTime* local,
              const openvdb::math::Transform& xform)
        : mSchedule(schedule), mT(t), mLocal(local && local->active() ? local : nullptr),
          mXform(xform),
          mVoxel(xform.voxelSize()[0]), mUniform{float(scheduleValue(schedule, t)),
                                                 float(scheduleSlope(schedule, t)), Vec3f(0.0f)}
    {
        if (mLocal)
            mMaxGradient = float(maxSlope(schedule) * mLocal->maxDelayGradient() /
                                 (1.0 - mLocal->spread()) * mVoxel);
    }

    /// True when every voxel has the same tau (no timing).
    bool uniform() const { return mLocal == nullptr; }
    /// The tau every voxel has when uniform().
    const VoxelTau& atAll() const { return mUniform; }
    /// A bound on |grad tau| per index unit anywhere (0 when uniform).
    float maxGradient() const { return mMaxGradient; }

    /// True when tau is clamped (not begun, or done) everywhere within `radius` voxels of index
    /// point ijk (never without a timing).
    bool clampedNear(const Vec3d& ijk, double radius) const
    {
        double tau;
        return mLocal && mLocal->clampedWithin(mXform.indexToWorld(ijk), radius * mVoxel, mT, tau);
    }

    /// The delay at index point ijk (for several schedules at one voxel: delayAt, then fromDelay).
    Delay delayAt(const Vec3d& ijk) const
    {
        return mLocal ? mLocal->delay(mXform.indexToWorld(ijk)) : Delay{};
    }
    VoxelTau fromDelay(const Delay& delay) const
    {
        if (!mLocal) return mUniform;
        const LocalTau local = mLocal->fromDelay(delay, mT);
        const double slope = scheduleSlope(mSchedule, local.tau);
        return {float(scheduleValue(mSchedule, local.tau)), float(slope * local.dt),
                Vec3f(local.gradient * (slope * mVoxel))};
    }
    VoxelTau at(const openvdb::Coord& ijk) const
    {
        return mLocal ? fromDelay(delayAt(ijk.asVec3d())) : mUniform;
    }

private:
    /// The schedule's steepest slope (sampled finely: linear 1, smoothstep 1.5, ...).
    static double maxSlope(const ScheduleSpec& schedule)
    {
        double most = 0.0;
        if (schedule.kind == ScheduleSpec::Kind::Curve) {
            const auto& p = schedule.points;
            for (size_t i = 1; i < p.size(); ++i)
                most =
                    std::max(most, (p[i].second - p[i - 1].second) / (p[i].first - p[i - 1].first));
            return most;
        }
        for (int i = 0; i <= 1000; ++i) most = std::max(most, scheduleSlope(schedule, i / 1000.0));
        return most * 1.01;
    }

    const ScheduleSpec& mSchedule;
    double mT;
    const LocalTime* mLocal;
    const openvdb::math::Transform& mXform;
    double mVoxel;
    VoxelTau mUniform;
    float mMaxGradient = 0.0f;
};

} // namespace volmorph::detail
