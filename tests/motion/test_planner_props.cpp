// Seeded property tests: random programs (lines, arcs, helices, short and long moves, corners of
// every angle, exact stops, rapids) streamed through planner -> ring -> sampler at 1 kHz, with
// overrides changing mid-run, holds and aborts. Every servo period is checked: per-axis velocity,
// acceleration and jerk (analytic and finite differences) within the limits (1e-6 relative),
// distance from the programmed path within the tolerance, no NaN; every program that is not
// aborted ends exactly at its programmed end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "program_gen.hpp"

namespace motion::test {
namespace {

PlannerConfig config(std::mt19937_64& rng, bool jerk, std::size_t window) {
    PlannerConfig cfg;
    cfg.limits = random_limits(rng, jerk);
    cfg.window = window;
    return cfg;
}

void expect_clean_finish(const PlayReport& rep, const Program& prog, std::uint64_t seed) {
    EXPECT_EQ(rep.violation, "") << "seed " << seed;
    EXPECT_FALSE(rep.starved) << "seed " << seed;
    ASSERT_TRUE(rep.done) << "seed " << seed << " did not finish in " << rep.periods << " periods";
    for (int k = 0; k < kAxes; ++k)
        EXPECT_NEAR(rep.last.pos_mm[k], prog.segs.back().end_mm[k], 1e-9) << "seed " << seed;
}

class RandomPrograms : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(RandomPrograms, TrapezoidalStayWithinLimitsAndToleranceAndEndExactly) {
    std::uint64_t seed = GetParam();
    std::mt19937_64 rng(seed);
    Program prog = random_program(rng, {});
    PlannerConfig cfg = config(rng, false, seed % 2 ? 4096 : 6);  // odd seeds: tiny window
    expect_clean_finish(play(cfg, prog, nullptr, {}), prog, seed);
}

TEST_P(RandomPrograms, JerkLimitedStayWithinLimitsAndToleranceAndEndExactly) {
    std::uint64_t seed = GetParam() + 1000;
    std::mt19937_64 rng(seed);
    Program prog = random_program(rng, {});
    PlannerConfig cfg = config(rng, true, seed % 2 ? 4096 : 6);
    expect_clean_finish(play(cfg, prog, nullptr, {}), prog, seed);
}

TEST_P(RandomPrograms, OverridesChangingMidRunKeepLimits) {
    std::uint64_t seed = GetParam() + 2000;
    std::mt19937_64 rng(seed);
    Program prog = random_program(rng, {20, true});
    PlannerConfig cfg = config(rng, seed % 2 == 0, 64);
    std::uniform_real_distribution<double> u(0, 1);
    // A new override every 50..500 ms: 0, 120 % and values between.
    std::vector<std::pair<long, double>> plan;
    long t = 0;
    for (int i = 0; i < 200; ++i) {
        t += 50 + long(u(rng) * 450);
        double r = u(rng);
        plan.emplace_back(t, r < 0.15 ? 0.0 : r < 0.4 ? 1.2 : 0.05 + 1.15 * u(rng));
    }
    auto script = [&](long n, Sampler& s) {
        for (const auto& [at, value] : plan)
            if (at == n) s.set_feed_override(value);
        if (n == plan.back().first + 1) s.set_feed_override(1.0);
    };
    expect_clean_finish(play(cfg, prog, script, {}), prog, seed);
}

TEST_P(RandomPrograms, HoldsStopAndResumeWithinLimits) {
    std::uint64_t seed = GetParam() + 3000;
    std::mt19937_64 rng(seed);
    Program prog = random_program(rng, {20, true});
    PlannerConfig cfg = config(rng, seed % 2 == 1, 64);
    std::uniform_real_distribution<double> u(0, 1);
    long hold_at = 100 + long(u(rng) * 3000), release_at = hold_at + 200 + long(u(rng) * 2000);
    long held_from = -1;
    auto script = [&](long n, Sampler& s) {
        if (n == hold_at) s.set_hold(true);
        if (n == release_at) s.set_hold(false);
        if (n < release_at && s.status().held && held_from < 0) held_from = n;
    };
    PlayReport rep = play(cfg, prog, script, {});
    expect_clean_finish(rep, prog, seed);
    // Once the hold has taken effect the machine does not move until released.
    if (held_from >= 0) {
        for (long n = held_from; n < release_at && n < long(rep.samples.size()); ++n)
            EXPECT_EQ(rep.samples[n].pos_mm, rep.samples[held_from].pos_mm) << "seed " << seed;
    }
}

TEST_P(RandomPrograms, AbortStopsWithinLimitsAndStaysStopped) {
    std::uint64_t seed = GetParam() + 4000;
    std::mt19937_64 rng(seed);
    Program prog = random_program(rng, {30, true});
    PlannerConfig cfg = config(rng, seed % 2 == 0, 64);
    std::uniform_real_distribution<double> u(0, 1);
    long abort_at = 50 + long(u(rng) * 2000);
    auto script = [&](long n, Sampler& s) {
        if (n == abort_at) s.abort();
    };
    PlayOptions opt;
    PlayReport rep = play(cfg, prog, script, opt);
    EXPECT_EQ(rep.violation, "") << "seed " << seed;
    if (!rep.done) {
        ASSERT_TRUE(rep.aborted) << "seed " << seed;
        // From full speed a stop takes at most (max_rate / r'max) plus the r'' ramps.
        RateLimits rl = rate_limits(sampler_config(cfg));
        double bound_s =
            cfg.max_rate / rl.max_rate_per_s + 2 * rl.max_rate_per_s / rl.max_rate_per_s2;
        // With a jerk limit the 1 % fixed bounds alone would take over 10 s; the room the plan
        // leaves brings it down to 0.1 s on average, 0.41 s at most over 200 seeds (0.70 s and
        // 1.68 s with the 10 % reserve before).
        if (seed % 2 == 0) bound_s = std::min(bound_s, 1.0);
        EXPECT_LE((rep.periods - abort_at) * 1e-3, bound_s + 0.01) << "seed " << seed;
    }
}

// Regression: with a jerk limit the speed reachable over an element is not monotone in the
// speed at its other end, and a later planning round once lowered a junction bound below what
// the already emitted speed could slow down to; the record's ramp then ran past its element.
TEST(RandomProgramsPlanOnly, StreamingWithJerkNeverPlansARampLongerThanItsElement) {
    for (std::uint64_t seed = 1; seed <= 300; ++seed) {
        std::mt19937_64 rng(seed * 7 + 1);
        Program prog = random_program(rng, {60, true});
        PlannerConfig cfg = config(rng, true, seed % 3 == 0 ? 6 : 50);
        Planner planner(cfg, prog.start);
        PreparedSegment rec;
        auto check = [&] {
            while (planner.pop(rec)) {
                double end_s = rec.profile.at(rec.profile.duration_s).s_mm;
                ASSERT_NEAR(end_s, rec.geom.length_mm, 1e-9 * std::max(1.0, rec.geom.length_mm))
                    << "seed " << seed << " line " << rec.line;
            }
        };
        for (const PathSegment& s : prog.segs) {
            planner.push(s);
            check();
        }
        planner.finish();
        check();
    }
}

// Corners with arcs (blended by Bezier curves): mostly arcs and helices meeting lines and each
// other at random angles, every corner with a tolerance. Odd seeds are jerk-limited, with high
// limits (1e6 .. 1e8 mm/s^3) under which the blends' curvature steps are allowed.
TEST_P(RandomPrograms, ArcCornersStayWithinLimitsAndToleranceAndEndExactly) {
    const std::uint64_t seed = GetParam();
    const bool jerk = seed % 2 == 1;
    std::mt19937_64 rng(seed * 7919 + jerk);
    GenOptions opt;
    opt.count = 12;
    opt.arc_corners = true;
    Program prog = random_program(rng, opt);
    PlannerConfig cfg = config(rng, jerk, seed % 4 < 2 ? 4096 : 6);
    for (double& j : cfg.limits.jerk_mm_s3) j *= 100;
    expect_clean_finish(play(cfg, prog, nullptr, {}), prog, seed);
}

// Line corners next to short lines (cut on offset lines, one-sided where a line is short):
// long and short lines at 30-130 degree turns, every corner with a tolerance, no jerk limit
// (offset corners are made only without one) but the limits and feeds of the other tests.
TEST_P(RandomPrograms, LineCornersNextToShortLinesStayWithinLimitsAndToleranceAndEndExactly) {
    const std::uint64_t seed = GetParam();
    std::mt19937_64 rng(seed * 104729 + 17);
    GenOptions opt;
    opt.count = 30;
    opt.line_corners = true;
    Program prog = random_program(rng, opt);
    PlannerConfig cfg = config(rng, false, seed % 4 < 2 ? 4096 : 6);
    expect_clean_finish(play(cfg, prog, nullptr, {}), prog, seed);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomPrograms, ::testing::Range<std::uint64_t>(1, 31));

}  // namespace
}  // namespace motion::test
