// Blend schedules: tau(0) = 0, tau(1) = 1, monotone; the sigmoid's centre and a curve's points;
// slopes against central differences of the values.
#include <volmorph/Schedule.h>

#include <gtest/gtest.h>

#include <array>

using namespace volmorph;

namespace {

/// Linear, smoothstep, sigmoid(12) and a curve through (0.5, 0.8).
std::array<ScheduleSpec, 4> schedules()
{
    std::array<ScheduleSpec, 4> s;
    s[1].kind = ScheduleSpec::Kind::Smoothstep;
    s[2].kind = ScheduleSpec::Kind::Sigmoid;
    s[2].k = 12;
    s[3].kind = ScheduleSpec::Kind::Curve;
    s[3].points = {{0, 0}, {0.5, 0.8}, {1, 1}};
    return s;
}

} // namespace

TEST(Schedule, EndpointsAndMonotone)
{
    const auto [linear, smooth, sigmoid, curve] = schedules();
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

TEST(Schedule, SlopeIsTheValuesDerivative)
{
    const auto [linear, smooth, sigmoid, curve] = schedules();
    const double h = 1e-6;
    for (const ScheduleSpec* s : {&linear, &smooth, &sigmoid, &curve})
        for (double t : {0.1, 0.3, 0.45, 0.6, 0.9}) {
            const double difference =
                (scheduleValue(*s, t + h) - scheduleValue(*s, t - h)) / (2 * h);
            EXPECT_NEAR(scheduleSlope(*s, t), difference, 1e-6) << describe(*s) << " at " << t;
        }
    EXPECT_NEAR(scheduleSlope(curve, 0.25), 1.6, 1e-12);
    EXPECT_NEAR(scheduleSlope(curve, 0.75), 0.4, 1e-12);
    EXPECT_EQ(scheduleSlope(linear, 1.5), 0.0);
    EXPECT_EQ(scheduleSlope(smooth, -0.5), 0.0);
}
