// ProbeJog (G904): speeds, trips, the farthest point and the acceleration limit.
#include <gtest/gtest.h>

#include <cmath>

#include "motion/probe_jog.hpp"

namespace motion {
namespace {

constexpr double kDt = 1e-3;

AxisLimits limits(double v, double a) {
    AxisLimits l;
    l.vel_mm_s.fill(v);
    l.acc_mm_s2.fill(a);
    return l;
}

std::array<ProbeAxis, kProbeAxes> z_only(double speed, double travel, int input, bool level) {
    std::array<ProbeAxis, kProbeAxes> axes{};
    axes[2] = {input, level, speed, travel};
    return axes;
}

// Steps until finished (or max periods), checking the acceleration limit on every axis.
int run(ProbeJog& jog, double acc_limit, std::uint64_t inputs, int max_periods = 100000) {
    int n = 0;
    AxisArray v_before = jog.vel_mm_s();
    while (!jog.finished() && n < max_periods) {
        jog.step(kDt, inputs, 1.0);
        for (int k = 0; k < kAxes; ++k)
            EXPECT_LE(std::fabs(jog.vel_mm_s()[k] - v_before[k]), acc_limit * kDt + 1e-9) << k;
        v_before = jog.vel_mm_s();
        ++n;
    }
    return n;
}

TEST(ProbeJog, WithoutItsInputLandsExactlyOnTheFarthestPoint) {
    ProbeJog jog;
    jog.start(AxisArray{0, 0, -1}, z_only(-10, 2, 1, true), limits(100, 1000));
    const int n = run(jog, 1000, 0);
    // why: 2 mm at 10 mm/s with 0.01 s ramps at 1000 mm/s^2 takes 0.21 s; the landing is exact.
    EXPECT_EQ(jog.pos_mm()[2], -3);
    EXPECT_NEAR(n * kDt, 0.21, 0.003);
    EXPECT_FALSE(jog.tripped());
    EXPECT_EQ(jog.vel_mm_s()[2], 0);
}

TEST(ProbeJog, InputStopsTheAxisWithinTheBrakingDistance) {
    ProbeJog jog;
    jog.start(AxisArray{}, z_only(-10, 50, 3, true), limits(100, 1000));
    for (int i = 0; i < 300; ++i) jog.step(kDt, 0, 1.0);
    ASSERT_FALSE(jog.finished());
    EXPECT_EQ(jog.vel_mm_s()[2], -10);
    const double seen_mm = jog.pos_mm()[2];
    const int n = run(jog, 1000, std::uint64_t{1} << 3);
    EXPECT_TRUE(jog.tripped());
    // why: from 10 mm/s at 1000 mm/s^2: 10 periods of 9.5, 8.5 ... 0.5 um = 0.05 mm exactly.
    EXPECT_EQ(n, 10);
    EXPECT_NEAR(jog.pos_mm()[2], seen_mm - 0.05, 1e-12);
}

TEST(ProbeJog, TripPointIsWhereTheInputCameNotWhereTheAxisStopped) {
    ProbeJog jog;
    jog.start(AxisArray{0, 0, -1}, z_only(-10, 50, 3, true), limits(100, 1000));
    for (int i = 0; i < 300; ++i) jog.step(kDt, 0, 1.0);
    // why: 10 periods of ramp (0.05 mm) and 290 at 10 um: -1 - 0.05 - 2.9 = -3.95.
    EXPECT_NEAR(jog.pos_mm()[2], -3.95, 1e-12);
    EXPECT_EQ(jog.trip_mm()[2], jog.pos_mm()[2]);  // not tripped yet: where it is
    run(jog, 1000, std::uint64_t{1} << 3);
    // why: the input seen in period 301 answers the command of period 300 (-3.95); the axis
    // brakes 0.05 mm beyond it. X and Y take no part: where they stand.
    EXPECT_NEAR(jog.trip_mm()[2], -3.95, 1e-12);
    EXPECT_NEAR(jog.pos_mm()[2], -4.0, 1e-12);
    EXPECT_EQ(jog.trip_mm()[0], 0);
    EXPECT_EQ(jog.trip_mm()[1], 0);
}

TEST(ProbeJog, AnAxisThatDidNotTripReportsItsStop) {
    ProbeJog jog;
    jog.start(AxisArray{0, 0, -1}, z_only(-10, 2, 1, true), limits(100, 1000));
    run(jog, 1000, 0);
    EXPECT_EQ(jog.trip_mm()[2], -3);
}

TEST(ProbeJog, InputAlreadyAtItsLevelDoesNotMove) {
    ProbeJog jog;
    jog.start(AxisArray{0, 0, -1}, z_only(-10, 50, 0, false), limits(100, 1000));
    run(jog, 1000, 0);  // input 0 is FALSE = the level asked for
    EXPECT_TRUE(jog.tripped());
    EXPECT_EQ(jog.pos_mm()[2], -1);
}

TEST(ProbeJog, AxesRunOnTheirOwnAndAllMustTrip) {
    ProbeJog jog;
    std::array<ProbeAxis, kProbeAxes> axes{};
    axes[0] = {0, true, 20, 100};  // X+ at 20 mm/s until input 0
    axes[1] = {1, true, -5, 1};    // Y- at 5 mm/s, at most 1 mm, input 1 never comes
    jog.start(AxisArray{}, axes, limits(100, 1000));
    for (int i = 0; i < 100; ++i) jog.step(kDt, 0, 1.0);
    EXPECT_EQ(jog.vel_mm_s()[0], 20);
    EXPECT_EQ(jog.vel_mm_s()[1], -5);
    EXPECT_EQ(jog.vel_mm_s()[2], 0);
    run(jog, 1000, 1);
    EXPECT_EQ(jog.pos_mm()[1], -1);
    EXPECT_FALSE(jog.tripped());  // Y reached its 1 mm without input 1
}

TEST(ProbeJog, SpeedIsCappedByTheAxisAndScaledByTheOverride) {
    ProbeJog jog;
    jog.start(AxisArray{}, z_only(40, 1000, 2, true), limits(50, 1000));
    for (int i = 0; i < 200; ++i) jog.step(kDt, 0, 1.0);
    EXPECT_EQ(jog.vel_mm_s()[2], 40);
    for (int i = 0; i < 200; ++i) jog.step(kDt, 0, 1.2);  // 48: still under the axis's 50
    EXPECT_EQ(jog.vel_mm_s()[2], 48);
    for (int i = 0; i < 200; ++i) jog.step(kDt, 0, 0.5);
    EXPECT_EQ(jog.vel_mm_s()[2], 20);
    ProbeJog fast;
    fast.start(AxisArray{}, z_only(500, 1000, 2, true), limits(50, 1000));
    for (int i = 0; i < 200; ++i) fast.step(kDt, 0, 1.0);
    EXPECT_EQ(fast.vel_mm_s()[2], 50);
    for (int i = 0; i < 200; ++i) jog.step(kDt, 0, 0.0);  // held: at rest, not finished
    EXPECT_EQ(jog.vel_mm_s()[2], 0);
    EXPECT_FALSE(jog.finished());
}

TEST(ProbeJog, StopNowBrakesAndNeverTrips) {
    ProbeJog jog;
    jog.start(AxisArray{}, z_only(-10, 50, 3, true), limits(100, 1000));
    for (int i = 0; i < 100; ++i) jog.step(kDt, 0, 1.0);
    jog.stop_now();
    const int n = run(jog, 1000, std::uint64_t{1} << 3);
    EXPECT_EQ(n, 10);
    EXPECT_FALSE(jog.tripped());
}

// Seeded property: any speed, travel and limits: never beyond the farthest point, never over the
// acceleration limit, always at rest at the end.
TEST(ProbeJog, RandomMovesStayWithinTravelAndAcceleration) {
    std::uint64_t seed = 12345;
    auto rnd = [&seed] {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        return static_cast<double>(seed >> 11) / static_cast<double>(1ULL << 53);
    };
    for (int trial = 0; trial < 200; ++trial) {
        const double a = 50 + 2000 * rnd(), speed = (rnd() - 0.5) * 200, travel = 5 * rnd();
        ProbeJog jog;
        jog.start(AxisArray{}, z_only(speed == 0 ? 1 : speed, travel, 0, true), limits(80, a));
        double v_before = 0;
        for (int n = 0; n < 100000 && !jog.finished(); ++n) {
            jog.step(kDt, 0, 1.0);
            ASSERT_LE(std::fabs(jog.pos_mm()[2]), travel + 1e-12) << trial;
            ASSERT_LE(std::fabs(jog.vel_mm_s()[2] - v_before), a * kDt * (1 + 1e-12)) << trial;
            v_before = jog.vel_mm_s()[2];
        }
        ASSERT_TRUE(jog.finished());
        EXPECT_NEAR(std::fabs(jog.pos_mm()[2]), travel, 1e-9) << trial;
        EXPECT_EQ(jog.vel_mm_s()[2], 0);
    }
}

}  // namespace
}  // namespace motion
