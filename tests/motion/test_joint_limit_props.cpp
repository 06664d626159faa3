// Seeded property tests of joint limits: random programs (lines, arcs, helices, corners of every
// angle, short moves, exact stops, rapids; tests/motion/program_gen.hpp) planned and sampled at
// 1 kHz on a CoreXY machine whose motors (joint 0 = X + Y, joint 1 = X - Y) are slower than
// what its axes would ask of them. Every period the motors' velocity, acceleration and jerk
// (the sampled axis values mapped through the kinematics, and finite differences of the mapped
// positions, with the slack play()'s axis checks use) stay within the motor limits; play()
// itself checks the axes, the path tolerance and NaN, and the program ends exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "motion/kinematics.hpp"
#include "motion/limits.hpp"
#include "program_gen.hpp"

namespace motion::test {
namespace {

// Random axis limits, and motors A and B at 40-90 % of what X + Y would ask of them (Z's motor
// as fast as Z): both are always listed.
PlannerConfig corexy_config(std::mt19937_64& rng, bool jerk) {
    std::uniform_real_distribution<double> u(0.4, 0.9);
    PlannerConfig cfg;
    cfg.limits = random_limits(rng, jerk);
    cfg.window = 64;
    const AxisLimits& l = cfg.limits;
    std::vector<JointLimit> joints(3);
    for (int j = 0; j < 2; ++j) {
        joints[j].vel_mm_s = u(rng) * (l.vel_mm_s[0] + l.vel_mm_s[1]);
        joints[j].acc_mm_s2 = u(rng) * (l.acc_mm_s2[0] + l.acc_mm_s2[1]);
        if (jerk) joints[j].jerk_mm_s3 = u(rng) * (l.jerk_mm_s3[0] + l.jerk_mm_s3[1]);
    }
    set_linear_joints(cfg.limits, CoreXYKinematics().linear_map(), joints);
    return cfg;
}

// The first period at which a motor leaves its limits, or "".
std::string joint_violation(const PlannerConfig& cfg, const PlayReport& rep, double dt) {
    const JointLimits& jl = cfg.limits.joints;
    const double rel = 1 + 1e-6;
    std::vector<double> p1(jl.count), p2(jl.count), a1(jl.count);
    for (std::size_t n = 0; n < rep.samples.size(); ++n) {
        const MotionSample& s = rep.samples[n];
        std::ostringstream why;
        for (int j = 0; j < jl.count; ++j) {
            const double p = joint_component(jl, j, s.pos_mm);
            const double v = joint_component(jl, j, s.vel_mm_s);
            const double a = joint_component(jl, j, s.acc_mm_s2);
            const double jk = joint_component(jl, j, s.jerk_mm_s3);
            const double vmax = jl.vel_mm_s[j], amax = jl.acc_mm_s2[j], jmax = jl.jerk_mm_s3[j];
            if (std::fabs(v) > vmax * rel)
                why << "joint " << j << " velocity " << v << " > " << vmax;
            if (std::fabs(a) > amax * rel)
                why << "joint " << j << " acceleration " << a << " > " << amax;
            if (jmax > 0 && std::fabs(jk) > jmax * rel)
                why << "joint " << j << " jerk " << jk << " > " << jmax;
            if (n >= 1) {
                const double v_fd = (p - p1[j]) / dt;
                if (std::fabs(v_fd) > vmax * rel + 1e-6)
                    why << "joint " << j << " sampled velocity " << v_fd << " > " << vmax;
                const double j_fd = (a - a1[j]) / dt;
                if (jmax > 0 && std::fabs(j_fd) > jmax * rel + 1e-3)
                    why << "joint " << j << " sampled jerk " << j_fd << " > " << jmax;
            }
            if (n >= 2) {
                const double a_fd = (p - 2 * p1[j] + p2[j]) / (dt * dt);
                if (std::fabs(a_fd) > amax * rel + 1e-4)
                    why << "joint " << j << " sampled acceleration " << a_fd << " > " << amax;
            }
            p2[j] = p1[j];
            p1[j] = p;
            a1[j] = a;
        }
        if (!why.str().empty())
            return "period " + std::to_string(n) + " line " + std::to_string(s.line) + ": " +
                   why.str();
    }
    return "";
}

void expect_within_joint_limits(const PlannerConfig& cfg, const Program& prog,
                                const PlayReport& rep, std::uint64_t seed, bool expect_end) {
    ASSERT_EQ(cfg.limits.joints.count, 2) << "seed " << seed;
    EXPECT_EQ(rep.violation, "") << "seed " << seed;
    EXPECT_EQ(joint_violation(cfg, rep, 1e-3), "") << "seed " << seed;
    if (!expect_end) return;
    ASSERT_TRUE(rep.done) << "seed " << seed << " did not finish in " << rep.periods << " periods";
    for (int k = 0; k < kAxes; ++k)
        EXPECT_NEAR(rep.last.pos_mm[k], prog.segs.back().end_mm[k], 1e-9) << "seed " << seed;
}

class CoreXYPrograms : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(CoreXYPrograms, TrapezoidalKeepTheMotorsWithinTheirLimits) {
    const std::uint64_t seed = GetParam();
    std::mt19937_64 rng(seed);
    const Program prog = random_program(rng, {30, false});
    const PlannerConfig cfg = corexy_config(rng, false);
    expect_within_joint_limits(cfg, prog, play(cfg, prog, nullptr, {}), seed, true);
}

TEST_P(CoreXYPrograms, JerkLimitedKeepTheMotorsWithinTheirLimits) {
    const std::uint64_t seed = GetParam() + 500;
    std::mt19937_64 rng(seed);
    const Program prog = random_program(rng, {30, false});
    const PlannerConfig cfg = corexy_config(rng, true);
    expect_within_joint_limits(cfg, prog, play(cfg, prog, nullptr, {}), seed, true);
}

TEST_P(CoreXYPrograms, ArcCornersKeepTheMotorsWithinTheirLimits) {
    const std::uint64_t seed = GetParam() + 1000;
    std::mt19937_64 rng(seed);
    GenOptions opt{30, false, true};
    const Program prog = random_program(rng, opt);
    const PlannerConfig cfg = corexy_config(rng, seed % 2 == 0);
    expect_within_joint_limits(cfg, prog, play(cfg, prog, nullptr, {}), seed, true);
}

// Overrides from 0 to 120 % changing every 50-500 ms, then a hold and its release: the sampler's
// rate changes keep the motors within their limits too (jerk limited on even seeds).
TEST_P(CoreXYPrograms, OverridesAndAHoldKeepTheMotorsWithinTheirLimits) {
    const std::uint64_t seed = GetParam() + 1500;
    std::mt19937_64 rng(seed);
    const Program prog = random_program(rng, {20, false});
    const PlannerConfig cfg = corexy_config(rng, seed % 2 == 0);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<std::pair<long, double>> plan;
    long t = 0;
    for (int i = 0; i < 12; ++i) {
        t += 50 + long(u(rng) * 450);
        const double r = u(rng);
        plan.emplace_back(t, r < 0.15 ? 0.0 : r < 0.4 ? 1.2 : 0.05 + 1.15 * u(rng));
    }
    const long hold_at = t + 100 + long(u(rng) * 1000), release_at = hold_at + 300;
    auto script = [&](long n, Sampler& s) {
        for (const auto& [at, value] : plan)
            if (at == n) s.set_feed_override(value);
        if (n == plan.back().first + 1) s.set_feed_override(1.0);
        if (n == hold_at) s.set_hold(true);
        if (n == release_at) s.set_hold(false);
    };
    expect_within_joint_limits(cfg, prog, play(cfg, prog, script, {}), seed, true);
}

// An abort at a random moment stops within the motors' limits (jerk limited on odd seeds).
TEST_P(CoreXYPrograms, AbortKeepsTheMotorsWithinTheirLimits) {
    const std::uint64_t seed = GetParam() + 2000;
    std::mt19937_64 rng(seed);
    const Program prog = random_program(rng, {20, false});
    const PlannerConfig cfg = corexy_config(rng, seed % 2 == 1);
    std::uniform_real_distribution<double> u(0, 1);
    const long abort_at = 50 + long(u(rng) * 2000);
    auto script = [&](long n, Sampler& s) {
        if (n == abort_at) s.abort();
    };
    const PlayReport rep = play(cfg, prog, script, {});
    expect_within_joint_limits(cfg, prog, rep, seed, !rep.aborted);
}

INSTANTIATE_TEST_SUITE_P(Seeds, CoreXYPrograms, ::testing::Range<std::uint64_t>(1, 41));

// A diagonal move is slower than an axis-parallel one by exactly sqrt 2 at the motors' limits,
// and an axis-parallel one runs at the full motor speed: by hand, a 100 mm line from rest to
// rest at v = 100 mm/s, a = 0.99 x 1000 mm/s^2 (the 1 % reserve) takes L / v + v / a =
// 1.10101 s along X; along the diagonal v and a are both divided by sqrt 2:
// L / v' + v' / a' = 1.41421 + 0.10101 = 1.51523 s.
TEST(CoreXYLines, DiagonalAtMotorLimitsOverSqrt2AndXAtFullSpeed) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(1000);
    cfg.limits.acc_mm_s2.fill(1e5);
    set_linear_joints(cfg.limits, CoreXYKinematics().linear_map(),
                      std::vector<JointLimit>{{100, 1000, 0}, {100, 1000, 0}, {0, 0, 0}});
    auto time_of = [&](double x, double y) {
        Program prog;
        PathSegment s;
        s.end_mm[0] = x;
        s.end_mm[1] = y;
        s.feed_mm_s = 500;
        prog.segs.push_back(s);
        const PlayReport rep = play(cfg, prog, nullptr, {});
        EXPECT_EQ(joint_violation(cfg, rep, 1e-3), "");
        EXPECT_TRUE(rep.done);
        return rep.periods * 1e-3;
    };
    const double x_s = 100 / 100.0 + 100 / 990.0;
    const double diag_s =
        100 / (100 / std::sqrt(2.0)) + (100 / std::sqrt(2.0)) / (990 / std::sqrt(2.0));
    EXPECT_NEAR(time_of(100, 0), x_s, 2e-3);
    EXPECT_NEAR(time_of(100 / std::sqrt(2.0), 100 / std::sqrt(2.0)), diag_s, 2e-3);
}

}  // namespace
}  // namespace motion::test
