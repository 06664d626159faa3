// Single block's jerk-limited stop: the stop maths (jerk_stop.hpp) and the sampler landing on a
// block's end within the acceleration and jerk limits.
#include <gtest/gtest.h>

#include <cmath>

#include "motion/jerk_stop.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"

namespace motion {
namespace {

TEST(JerkStop, DistanceOfAHandWorkedStop) {
    // why: from 10 mm/s with jerk 1000 and peak 100 mm/s^2: piece 1 takes 0.1 s and 5 mm/s
    // (10 * 0.1 - 1000 * 0.1^3 / 6 = 0.8333 mm), piece 2 is empty (5 mm/s is what piece 3 loses),
    // piece 3 covers 5 * 0.1 - 100 * 0.1^2 / 2 + 1000 * 0.1^3 / 6 = 0.1667 mm: 1 mm in all.
    EXPECT_NEAR(jerk_stop_distance({10, 0}, 100, 1000), 1.0, 1e-12);
    EXPECT_NEAR(jerk_stop_max_peak({10, 0}, 1000), 100, 1e-12);
    // A lower peak adds piece 2 and a longer stop.
    EXPECT_GT(jerk_stop_distance({10, 0}, 50, 1000), 1.0);
}

TEST(JerkStop, FindsThePeakForTheDistanceOrNone) {
    const std::optional<double> d = jerk_stop_decel_for({10, 0}, 1.5, 1000, 1000);
    ASSERT_TRUE(d.has_value());
    EXPECT_NEAR(jerk_stop_distance({10, 0}, *d, 1000), 1.5, 1e-9);
    EXPECT_FALSE(jerk_stop_decel_for({10, 0}, 0.9, 1000, 1000).has_value());  // needs 1 mm
}

TEST(JerkStop, ReSolvedEveryPeriodItLandsExactlyWithinTheLimits) {
    JerkStopState s{40, 200};  // still accelerating when the stop starts
    const double j = 5000, a_max = 1000, dt = 1e-3;
    const double end_mm = 1.2 * jerk_stop_distance(s, a_max, j);  // room for a softer stop
    double pos = 0, a_before = s.a_mm_s2;
    int n = 0;
    for (; n < 10000; ++n) {
        const std::optional<double> d = jerk_stop_decel_for(s, end_mm - pos, a_max, j);
        ASSERT_TRUE(d.has_value()) << n;
        const JerkStopStep step = jerk_stop_step(s, *d, j, dt);
        pos += step.ds_mm;
        EXPECT_LE(std::fabs(step.next.a_mm_s2), a_max * (1 + 1e-9));
        EXPECT_LE(std::fabs(step.next.a_mm_s2 - a_before), j * dt * (1 + 1e-6)) << n;
        a_before = step.next.a_mm_s2;
        s = step.next;
        if (step.at_rest) break;
    }
    EXPECT_NEAR(pos, end_mm, 1e-9);
    EXPECT_EQ(s.v_mm_s, 0);
}

TEST(SingleBlockJerk, StopsOnTheBlockEndWithinTheJerkLimit) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(100);
    cfg.limits.acc_mm_s2.fill(1000);
    cfg.limits.jerk_mm_s3.fill(20000);
    SpscRing<PreparedSegment> ring(64);
    Planner p(cfg, {});
    for (int i = 1; i <= 2; ++i) {
        PathSegment seg;
        seg.end_mm = {10.0 * i};
        seg.feed_mm_s = 50;
        seg.tolerance_mm = 0.01;
        seg.line = i;
        p.push(seg);
    }
    p.finish();
    PreparedSegment r;
    while (p.pop(r)) ASSERT_TRUE(ring.try_push(r));
    Sampler sampler(sampler_config(cfg), ring, AxisArray{});
    sampler.set_single_block(true);
    MotionSample s{}, before{};
    double max_jerk = 0;
    int n = 0;
    for (; n < 10000 && !sampler.status().block_paused; ++n) {
        before = s;
        s = sampler.advance(1e-3);
        if (n > 0)
            max_jerk = std::max(max_jerk, std::fabs(s.acc_mm_s2[0] - before.acc_mm_s2[0]) / 1e-3);
        EXPECT_LE(std::fabs(s.acc_mm_s2[0]), 1000 * (1 + 1e-9)) << n;
    }
    ASSERT_TRUE(sampler.status().block_paused);
    // why: the plan runs through X10 at 50 mm/s; single block must stop exactly there, and the
    // stop's jerk stays within the axis's 20000 mm/s^3 (the constant-deceleration stop it
    // replaces stepped the acceleration by ~800 mm/s^2 in one period: 800 000 mm/s^3).
    EXPECT_EQ(s.pos_mm[0], 10);
    EXPECT_LE(max_jerk, 20000 * (1 + 1e-6));
}

}  // namespace
}  // namespace motion
