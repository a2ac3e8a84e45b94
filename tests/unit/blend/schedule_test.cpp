// Blend schedules: tau(0) = 0, tau(1) = 1, monotone; the sigmoid's centre and a curve's points.
#include <volmorph/Schedule.h>

#include <gtest/gtest.h>

using namespace volmorph;

TEST(Schedule, EndpointsAndMonotone)
{
    ScheduleSpec linear, smooth, sigmoid, curve;
    smooth.kind = ScheduleSpec::Kind::Smoothstep;
    sigmoid.kind = ScheduleSpec::Kind::Sigmoid;
    sigmoid.k = 12;
    curve.kind = ScheduleSpec::Kind::Curve;
    curve.points = {{0, 0}, {0.5, 0.8}, {1, 1}};
    for (const ScheduleSpec* s : {&linear, &smooth, &sigmoid, &curve}) {
        EXPECT_NEAR(scheduleValue(*s, 0.0), 0.0, 1e-12) << describe(*s);
        EXPECT_NEAR(scheduleValue(*s, 1.0), 1.0, 1e-12) << describe(*s);
        double previous = 0.0;
        for (int i = 1; i <= 100; ++i) {
            const double tau = scheduleValue(*s, i / 100.0);
            EXPECT_GE(tau, previous) << describe(*s);
            previous = tau;
        }
    }
    EXPECT_NEAR(scheduleValue(sigmoid, 0.5), 0.5, 1e-12);
    EXPECT_NEAR(scheduleValue(curve, 0.25), 0.4, 1e-12);
    EXPECT_NEAR(scheduleValue(curve, 0.75), 0.9, 1e-12);
}
