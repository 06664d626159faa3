// Sampler, jerk limited: feed-override increases ("raises") start at once and keep the limits.
// A raise towards a rate <= 1 tries r'' > 0 at the room the plan's jerk leaves on that side
// (nearly 2 J against a jerk phase, J in cruise) before the symmetric bounds, which gave r''
// only half of the jerk and nothing inside a jerk phase at r near 1
// (docs/motion-planner.md, "The realtime side").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "program_gen.hpp"
#include "sampler_support.hpp"

namespace motion {
namespace {

using test::feed_to;
using test::LimitCheck;
using test::uniform;

// A 300 mm X line at 100 mm/s (the axis's top speed) with A = 1000 mm/s^2, J = 10 000 mm/s^3,
// played at 50 % until well into its cruise (1.5 s of wall time: the acceleration from rest
// takes 0.2 s of planned time, 0.4 s at 50 %), then raised to 100 %. In cruise the plan has
// v = 100, a = 0, j = 0, so the tangential jerk is v r'' alone and the acceleration v r': the
// rate has r'' <= J / v = 100 / s^2 and r' <= A / v = 10 / s (times the 0.97 share) of room.
// Worked by hand:
// - the first period already rises at (nearly) the whole jerk: commanded jerk >= 0.9 J, and
//   r gains at least 0.9 (J / v) dt^2 / 2 = 4.5e-5 in it (the old symmetric bounds gave r''
//   half of J / v: jerk 0.5 J);
// - the speed has to go from 50 to 100 mm/s with a = 0 at both ends: the time-optimal
//   jerk-limited change peaks at ap = sqrt(J du) = 707 mm/s^2 < A and takes 2 ap / J =
//   0.1414 s; the rate gets to 1 within that plus 10 periods (the share of the room the moves
//   keep, the decisions at period boundaries), where the old bounds took 2 sqrt(du / (J / 2))
//   = 0.2 s.
TEST(SamplerRaises, RaiseInCruiseStartsAtOnceAndTakesAboutTheShortestJerkLimitedChange) {
    const double v = 100, acc = 1000, jerk = 1e4, dt = 1e-3;
    const PlannerConfig cfg = uniform(v, acc, jerk);
    SpscRing<PreparedSegment> ring(16);
    {
        Planner p(cfg, {});
        p.push(feed_to(300, v, 1));
        p.finish();
        PreparedSegment r;
        while (p.pop(r)) ring.try_push(r);
    }
    Sampler sampler(sampler_config(cfg), ring, AxisArray{});
    LimitCheck check(cfg.limits);
    sampler.set_feed_override(0.5);
    MotionSample m{};
    for (int n = 0; n < 1500; ++n) check(m = sampler.advance(dt), dt);
    ASSERT_DOUBLE_EQ(sampler.status().rate, 0.5);
    ASSERT_NEAR(m.vel_mm_s[0], 50, 1e-9);  // in cruise at half speed
    ASSERT_NEAR(m.acc_mm_s2[0], 0, 1e-9);
    sampler.set_feed_override(1.0);
    check(m = sampler.advance(dt), dt);
    EXPECT_GE(m.jerk_mm_s3[0], 0.9 * jerk);
    EXPECT_GE(sampler.status().rate - 0.5, 0.9 * (jerk / v) * dt * dt / 2);
    long periods = 1;
    while (sampler.status().rate < 1 - 1e-9 && periods < 1000) {
        check(m = sampler.advance(dt), dt);
        ++periods;
    }
    const double shortest_s = 2 * std::sqrt(jerk * (v - 50)) / jerk;  // 0.1414 s
    EXPECT_NEAR(shortest_s, 0.1414, 1e-4);
    EXPECT_LE(periods * dt, shortest_s + 10 * dt);
    EXPECT_GE(periods * dt, shortest_s - dt);  // no rise can be quicker
    for (int n = 0; n < 100; ++n) check(m = sampler.advance(dt), dt);
    EXPECT_DOUBLE_EQ(sampler.status().rate, 1.0);
    EXPECT_EQ(check.first(), "");
}

// The same line raised at every 5 ms of its acceleration from rest and its first 50 ms of
// cruise, from 10 %, 40 % and 70 %, at J = 10 000 and 100 000 mm/s^3: from r <= 0.7 the plan
// uses at most 0.49 of the acceleration and 0.34 of the jerk, so the rate has room at once and
// its own part of the path acceleration, v r', must reach J dt / 8 in the first or second
// period (what r'' at a quarter of the jerk gives in one period from r' = 0), or, where the
// plan barely moves (v r' stays small however fast r rises), r rise by 1 % of the step in a
// period, or the rate be at its target; and it gets there. The old sampler started only after
// up to 23 ms (bench_sampler --raises).
TEST(SamplerRaises, RaisesDuringTheAccelerationFromRestStartWithinTwoPeriods) {
    const double dt = 1e-3;
    for (double jerk : {1e4, 1e5}) {
        const PlannerConfig cfg = uniform(100, 1000, jerk);
        std::vector<PreparedSegment> recs;
        {
            Planner p(cfg, {});
            p.push(feed_to(200, 100, 1));
            p.finish();
            PreparedSegment r;
            while (p.pop(r)) recs.push_back(r);
        }
        const double accel_s = 100.0 / 1000 + 1000 / jerk;  // v / A + A / J (v >= A^2 / J)
        for (double before : {0.1, 0.4, 0.7}) {
            const long last_ms = long(accel_s / before * 1000) + 50;
            for (long at = 5; at <= last_ms; at += 5) {
                SpscRing<PreparedSegment> ring(recs.size() + 1);
                for (const auto& r : recs) ring.try_push(r);
                Sampler sampler(sampler_config(cfg), ring, AxisArray{});
                LimitCheck check(cfg.limits);
                sampler.set_feed_override(before);
                MotionSample m{};
                for (long n = 0; n < at; ++n) check(m = sampler.advance(dt), dt);
                sampler.set_feed_override(1.0);
                double r_prev = sampler.status().rate;
                long started = -1, there = -1;
                for (long n = 1; n <= 2000 && there < 0; ++n) {
                    check(m = sampler.advance(dt), dt);
                    const double r = sampler.status().rate;
                    const double plan_v = r > 0 ? std::fabs(m.vel_mm_s[0]) / r : 0;
                    if (started < 0 &&
                        (r >= 1 - 1e-9 || plan_v * (r - r_prev) / dt >= jerk * dt / 8 ||
                         r - r_prev >= 0.01 * (1 - before)))
                        started = n;
                    if (r >= 1 - 1e-9) there = n;
                    r_prev = r;
                }
                ASSERT_EQ(check.first(), "") << "J " << jerk << " " << before << " at " << at;
                EXPECT_GE(started, 1);
                EXPECT_LE(started, 2)
                    << "J " << jerk << " from " << before << " at " << at << " ms";
                EXPECT_GE(there, 1) << "J " << jerk << " from " << before << " at " << at << " ms";
            }
        }
    }
}

// Seeded random programs (lines, arcs, helices, corners, exact stops, rapids) streamed through
// planner -> ring -> sampler with a jerk limit: the override drops to a low value and is raised
// again at random instants (so raises land in jerk phases, acceleration phases, cruise, arcs
// and next to the ring's end), to targets up to 120 %. Every period keeps every axis's
// velocity, acceleration and jerk (analytic and finite differences) within the limits, the path
// within its tolerance, no NaN (test::play()), and the program ends exactly at its end.
class RandomRaises : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(RandomRaises, RaisesAtRandomInstantsKeepTheLimits) {
    const std::uint64_t seed = GetParam() + 7000;
    std::mt19937_64 rng(seed);
    const test::Program prog = test::random_program(rng, {24, true});
    PlannerConfig cfg;
    cfg.limits = test::random_limits(rng, true);
    cfg.window = 64;
    std::uniform_real_distribution<double> u(0, 1);
    // Low for 5-200 ms, then raised for 10-400 ms, over and over.
    std::vector<std::pair<long, double>> plan;
    long t = 0;
    for (int i = 0; i < 160; ++i) {
        t += 5 + long(u(rng) * 195);
        const double low = 0.02 + 0.6 * u(rng);
        plan.emplace_back(t, low);
        t += 10 + long(u(rng) * 390);
        plan.emplace_back(t, u(rng) < 0.25 ? 1.2 : low + (1 - low) * (0.2 + 0.8 * u(rng)));
    }
    long raises_taken = 0;
    double rate_at_raise = -1;
    auto script = [&](long n, Sampler& s) {
        for (const auto& [at, value] : plan) {
            if (at != n) continue;
            if (value > s.status().rate) rate_at_raise = s.status().rate;
            s.set_feed_override(value);
        }
        if (rate_at_raise >= 0 && s.status().rate > rate_at_raise + 1e-6) {
            ++raises_taken;
            rate_at_raise = -1;
        }
        if (n == plan.back().first + 1) s.set_feed_override(1.0);
    };
    const test::PlayReport rep = test::play(cfg, prog, script, {});
    EXPECT_EQ(rep.violation, "") << "seed " << seed;
    EXPECT_FALSE(rep.starved) << "seed " << seed;
    ASSERT_TRUE(rep.done) << "seed " << seed;
    for (int k = 0; k < kAxes; ++k)
        EXPECT_NEAR(rep.last.pos_mm[k], prog.segs.back().end_mm[k], 1e-9) << "seed " << seed;
    // The test exercised raises at all (unless the program ended before the first one).
    if (rep.periods > plan[1].first + 20) {
        EXPECT_GT(raises_taken, 0)
            << "seed " << seed << ": " << rep.periods << " periods, " << plan[0].second << " at "
            << plan[0].first << ", " << plan[1].second << " at " << plan[1].first;
    }
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomRaises, ::testing::Range<std::uint64_t>(1, 41));

}  // namespace
}  // namespace motion
