// 1-D profiles: closed forms checked against hand computations and against each other.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "motion/profile.hpp"

namespace motion {
namespace {

TEST(Profile, TrapezoidRestToRestTakesLengthOverSpeedPlusSpeedOverAcc) {
    // 100 mm at 50 mm/s with 500 mm/s^2: ramps of 0.1 s covering 2.5 mm each, 95 mm cruise.
    Profile1D p = build_profile(100, 0, 0, 50, {500, 0});
    EXPECT_NEAR(p.duration_s, 100.0 / 50 + 50.0 / 500, 1e-12);
    EXPECT_NEAR(p.at(p.duration_s).s_mm, 100, 1e-9);
    EXPECT_NEAR(p.at(0.1).v_mm_s, 50, 1e-9);
    EXPECT_NEAR(p.at(0.05).s_mm, 0.5 * 500 * 0.05 * 0.05, 1e-12);
}

TEST(Profile, ShortTrapezoidIsATriangle) {
    // 1 mm with 1000 mm/s^2 from rest to rest: peak sqrt(a L) = 31.6 mm/s, time 2 sqrt(L/a).
    Profile1D p = build_profile(1, 0, 0, 100, {1000, 0});
    EXPECT_NEAR(p.peak_v_mm_s, std::sqrt(1000.0), 1e-9);
    EXPECT_NEAR(p.duration_s, 2 * std::sqrt(1 / 1000.0), 1e-12);
}

TEST(Profile, SCurveRampMatchesTextbookTimes) {
    // dv = 100 with A = 1000, J = 10000: A^2/J = 100 = dv, so the ramp just reaches A:
    // two jerk phases of A/J = 0.1 s, total 0.2 s, mean speed 50 -> 10 mm.
    TangentLimits lim{1000, 10000};
    EXPECT_NEAR(ramp_time_s(100, lim), 0.2, 1e-12);
    EXPECT_NEAR(ramp_distance_mm(0, 100, lim), 10, 1e-12);
    // dv = 400: 0.1 s jerk, 0.3 s at A, 0.1 s jerk.
    EXPECT_NEAR(ramp_time_s(400, lim), 0.5, 1e-12);
    Profile1D p = build_profile(1000, 0, 0, 400, lim);
    EXPECT_NEAR(p.peak_a_mm_s2, 1000, 1e-9);
    EXPECT_NEAR(p.at(0.5).v_mm_s, 400, 1e-9);
    EXPECT_NEAR(p.at(0.05).a_mm_s2, 500, 1e-9);
    EXPECT_NEAR(p.at(0.05).s_mm, 10000 * 0.05 * 0.05 * 0.05 / 6, 1e-12);
}

TEST(Profile, ReachableSpeedInvertsRampDistance) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 20000; ++i) {
        TangentLimits lim{50 + 5000 * u(rng), u(rng) < 0.3 ? 0 : 1e3 + 1e6 * u(rng)};
        double v0 = 200 * u(rng) * u(rng);
        double len = std::pow(10, -4 + 6 * u(rng));
        double v1 = reachable_speed_mm_s(v0, len, lim);
        ASSERT_GE(v1, v0);
        ASSERT_NEAR(ramp_distance_mm(v0, v1, lim), len, 1e-9 * std::max(1.0, len))
            << "v0 " << v0 << " len " << len << " A " << lim.acc_mm_s2 << " J " << lim.jerk_mm_s3;
    }
}

TEST(Profile, RandomProfilesEndAtLengthAndSpeedWithinLimits) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 20000; ++i) {
        TangentLimits lim{50 + 5000 * u(rng), u(rng) < 0.3 ? 0 : 1e3 + 1e6 * u(rng)};
        double len = std::pow(10, -4 + 6 * u(rng));
        double vcap = 1 + 300 * u(rng);
        double v_in = vcap * u(rng);
        double v_out = std::min(vcap, reachable_speed_mm_s(v_in, len, lim)) * u(rng);
        // make v_in reachable backwards from v_out too
        v_in = std::min(v_in, reachable_speed_mm_s(v_out, len, lim));
        Profile1D p = build_profile(len, v_in, v_out, vcap, lim);
        PathState end = p.at(p.duration_s);
        ASSERT_NEAR(end.s_mm, len, 1e-9 * std::max(1.0, len));
        ASSERT_NEAR(end.v_mm_s, v_out, 1e-7 * std::max(1.0, vcap));
        ASSERT_LE(p.peak_v_mm_s, vcap * (1 + 1e-12));
        ASSERT_LE(p.peak_a_mm_s2, lim.acc_mm_s2 * (1 + 1e-9));
        if (lim.jerk_mm_s3 > 0) {
            ASSERT_LE(p.peak_j_mm_s3, lim.jerk_mm_s3 * (1 + 1e-12));
        }
        // s(t) is monotone and v(t) matches its derivative
        double prev = -1;
        for (int k = 0; k <= 50; ++k) {
            double t = p.duration_s * k / 50;
            PathState st = p.at(t);
            ASSERT_GE(st.s_mm, prev - 1e-12);
            ASSERT_GE(st.v_mm_s, 0);
            ASSERT_LE(st.v_mm_s, vcap * (1 + 1e-9));
            prev = st.s_mm;
        }
    }
}

}  // namespace
}  // namespace motion
