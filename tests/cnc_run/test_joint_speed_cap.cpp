// The plan-time joint speed cap under a nonlinear kinematics (JointLimitCheck::speed_cap_mm_s,
// components/motion/joint_limits.hpp) on moves whose joint rates are known in closed form, and
// its absence under a linear kinematics. The path length s counts rotary degrees as mm, as the
// planner's does: a C rotation of a point at radius r moves machine X and Y at most
// r pi / 180 mm per degree of s.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "joint_limits.hpp"
#include "kins_link.hpp"
#include "motion/geometry.hpp"
#include "motion/kinematics.hpp"

namespace {

using motioncomp::JointLimitCheck;
using motioncomp::JointLimitConfig;
using motioncomp::PlanningKinematics;

constexpr double kDeg = std::numbers::pi / 180;
constexpr double kMaxRate = 1.2;  // motion's highest feed override

// configs/sim/5axis-trt.ini's joints: X Y Z A C, the A axis 80 mm below the workpiece origin.
JointLimitConfig trt(std::vector<double> max_velocity, std::vector<double> max_acceleration) {
    motion::TrtPivots p;
    p.a_pivot_mm = Eigen::Vector3d(0, 0, -80);
    JointLimitConfig cfg;
    cfg.kins = std::make_shared<PlanningKinematics>(
        nullptr, std::make_unique<motion::XyzacTrtKinematics>(p));
    cfg.min_limit.assign(5, -1e9);
    cfg.max_limit.assign(5, 1e9);
    cfg.max_velocity = std::move(max_velocity);
    cfg.max_acceleration = std::move(max_acceleration);
    cfg.max_rate = kMaxRate;
    return cfg;
}

motion::AxisArray at(double x, double y, double z, double a, double c) {
    motion::AxisArray p{};
    p[0] = x, p[1] = y, p[2] = z, p[3] = a, p[5] = c;
    return p;
}

// The axes of 5axis-trt.ini (X Y Z A C: 100 100 50 90 180 per s) allow a path speed of
// min_k vel_k / |p'_k| on a line; kAxesFree: no axis limit binds.
constexpr double kAxesFree = INFINITY;
double axes_speed(const motion::Element& line) {
    const double vel[motion::kAxes] = {100, 100, 50, 90, 1e9, 180, 1e9, 1e9, 1e9};
    double v = INFINITY;
    for (int k = 0; k < motion::kAxes; ++k)
        if (line.a[k] != 0) v = std::min(v, vel[k] / std::fabs(line.a[k]));
    return v;
}

// The sampled cap may be up to about 0.1 % below the exact one (the allowance), never above it.
void expect_cap(double cap, double exact) {
    EXPECT_LE(cap, exact * (1 + 1e-9));
    EXPECT_GE(cap, exact * (1 - 1.5e-3));
}

TEST(JointSpeedCap, CRotationAtRadiusIsCappedByTheLinearMotorsVelocity) {
    // A = 0, a point 42 mm off the C axis turned through 200 degrees: X = 42 cos C and
    // Y = 42 sin C each reach |dq/ds| = 42 pi / 180 = 0.733 mm/deg; joint C moves 1 deg/deg.
    const double r = 42;
    JointLimitCheck check(trt({100, 100, 50, 90, 180}, {0, 0, 0, 0, 0}));
    const motion::Element near = motion::make_line(at(r, 0, 0, 0, 0), at(r, 0, 0, 0, 200));
    expect_cap(check.speed_cap_mm_s(near, kAxesFree), 100 / (r * kDeg) / kMaxRate);
    // C's own 180 deg/s allows more than X's and Y's 136 deg/s here: the cap stands.
    expect_cap(check.speed_cap_mm_s(near, axes_speed(near)), 100 / (r * kDeg) / kMaxRate);
    // 300 mm off the axis: 5.2 mm/deg, 19 deg/s.
    const motion::Element far = motion::make_line(at(300, 0, 0, 0, 0), at(300, 0, 0, 0, 200));
    expect_cap(check.speed_cap_mm_s(far, axes_speed(far)), 100 / (300 * kDeg) / kMaxRate);
    // 10 mm off the axis: the motors X, Y allow 573 deg/s, above C's 180: no cap.
    const motion::Element close = motion::make_line(at(10, 0, 0, 0, 0), at(10, 0, 0, 0, 200));
    EXPECT_EQ(check.speed_cap_mm_s(close, axes_speed(close)), INFINITY);
}

TEST(JointSpeedCap, CRotationCurvatureTakesHalfTheAcceleration) {
    // d2X/ds2 = -r cos C (pi / 180)^2: |h| <= r (pi / 180)^2; v^2 |h| <= 0.5 * 1000.
    const double r = 42;
    JointLimitCheck check(trt({0, 0, 0, 0, 0}, {1000, 1000, 500, 900, 1800}));
    const double cap =
        check.speed_cap_mm_s(motion::make_line(at(r, 0, 0, 0, 0), at(r, 0, 0, 0, 200)), kAxesFree);
    expect_cap(
        cap, std::sqrt(JointLimitCheck::kCurvatureAccShare * 1000 / (r * kDeg * kDeg)) / kMaxRate);
}

TEST(JointSpeedCap, YMoveOnATiltedTableIsCappedByTheZMotor) {
    // At A = -65 a workpiece Y move drives machine Z at |sin 65| = 0.906 mm/mm and machine Y at
    // cos 65 = 0.423: Z (50 mm/s) binds at 55.2 mm/s, below Y's own 100.
    JointLimitCheck check(trt({100, 100, 50, 90, 180}, {1000, 1000, 500, 900, 1800}));
    const motion::Element y = motion::make_line(at(0, -40, 0, -65, 0), at(0, 40, 0, -65, 0));
    expect_cap(check.speed_cap_mm_s(y, axes_speed(y)), 50 / std::sin(65 * kDeg) / kMaxRate);
    // An X move at that tilt drives machine X only, as fast as the X axis: no cap.
    const motion::Element x = motion::make_line(at(-40, 0, 0, -65, 0), at(40, 0, 0, -65, 0));
    EXPECT_EQ(check.speed_cap_mm_s(x, axes_speed(x)), INFINITY);
    // Without the axis limits it would be the X motor's 100 at the highest override.
    expect_cap(check.speed_cap_mm_s(x, kAxesFree), 100 / kMaxRate);
}

TEST(JointSpeedCap, ArcOnALevelTableIsLeftToThePlanner) {
    // An XY arc at A = C = 0 maps straight to joints X, Y: |dq/ds| <= 1 each, and the joints add
    // no curvature of their own (the path's, 1/r, the planner limits through the axes).
    JointLimitCheck check(trt({100, 100, 50, 90, 180}, {1000, 1000, 500, 900, 1800}));
    motion::PathSegment arc;
    arc.kind = motion::SegmentKind::Arc;
    arc.end_mm = at(-10, 0, 0, 0, 0);
    arc.centre_mm = {0, 0};
    arc.turns = 1;
    const motion::Element e = motion::make_arc(at(10, 0, 0, 0, 0), arc);
    expect_cap(check.speed_cap_mm_s(e, kAxesFree), 100 / kMaxRate);
    EXPECT_EQ(check.speed_cap_mm_s(e, 100), INFINITY);  // the axes' 100 mm/s keep the motors'
}

// Seeded random lines turning A and C (the kinematics' own curvature is all of d2q/ds2 on a
// line) and XY arcs with A and C moving too (velocity only), against brute force: each joint's
// max |dq/ds| and |d2q/ds2| from 20 000 samples of differences along s (point_at, a step of
// 1e-4 of the length, not the check's tangent direction). The cap may be up to 0.15 % below
// the exact one and never above it (more than rounding).
TEST(JointSpeedCap, RandomTrtMovesAgreeWithBruteForce) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> xy(-100, 100), z(-60, 0), a(-90, 90), c(-400, 400);
    auto point = [&] { return at(xy(rng), xy(rng), z(rng), a(rng), c(rng)); };
    const std::vector<double> vel = {100, 100, 50, 90, 180}, acc = {1000, 1000, 500, 900, 1800};
    motion::XyzacTrtKinematics kins([] {
        motion::TrtPivots p;
        p.a_pivot_mm = Eigen::Vector3d(0, 0, -80);
        return p;
    }());
    double worst_low = 1;
    for (int i = 0; i < 60; ++i) {
        const bool arc = i % 2 == 1;
        const motion::AxisArray start = point();
        motion::Element e;
        if (arc) {
            motion::PathSegment seg;
            seg.kind = motion::SegmentKind::Arc;
            seg.end_mm = point();
            const double r = std::uniform_real_distribution<double>(5, 80)(rng);
            const double from = std::uniform_real_distribution<double>(0, 6.28)(rng);
            const double to = std::uniform_real_distribution<double>(0, 6.28)(rng);
            seg.centre_mm = {start[0] - r * std::cos(from), start[1] - r * std::sin(from)};
            seg.end_mm[0] = seg.centre_mm[0] + r * std::cos(to);
            seg.end_mm[1] = seg.centre_mm[1] + r * std::sin(to);
            seg.turns = i % 4 == 1 ? 1 : -1;
            e = motion::make_arc(start, seg);
        } else {
            e = motion::make_line(start, point());
        }
        constexpr int kSamples = 20000;
        const double h = e.length_mm * 1e-4;
        std::vector<double> qm(5), q0(5), qp(5);
        std::array<double, 5> g{}, c2{};
        for (int k = 0; k <= kSamples; ++k) {
            // Within [h, length - h]: the path is not extended past its ends.
            const double s = h + (e.length_mm - 2 * h) * k / kSamples;
            kins.inverse(motion::point_at(e, s - h), qm);
            kins.inverse(motion::point_at(e, s), q0);
            kins.inverse(motion::point_at(e, s + h), qp);
            for (std::size_t n = 0; n < 5; ++n) {
                g[n] = std::max(g[n], std::fabs(qp[n] - qm[n]) / (2 * h));
                c2[n] = std::max(c2[n], std::fabs(qp[n] - 2 * q0[n] + qm[n]) / (h * h));
            }
        }
        double exact = INFINITY;
        for (std::size_t n = 0; n < 5; ++n) {
            exact = std::min(exact, vel[n] / g[n]);
            if (!arc) exact = std::min(exact, std::sqrt(0.5 * acc[n] / c2[n]));
        }
        JointLimitCheck check(trt(vel, arc ? std::vector<double>(5, 0.0) : acc));
        const double cap = check.speed_cap_mm_s(e, kAxesFree) * kMaxRate;
        SCOPED_TRACE(::testing::Message() << "move " << i << (arc ? " arc" : " line"));
        EXPECT_LE(cap, exact * (1 + 1e-6));
        EXPECT_GE(cap, exact * (1 - 1.5e-3));
        worst_low = std::min(worst_low, cap / exact);
    }
    std::printf("lowest cap / exact: %.6f\n", worst_low);
}

TEST(JointSpeedCap, NoneWithoutJointRatesToPlan) {
    const motion::Element c = motion::make_line(at(42, 0, 0, 0, 0), at(42, 0, 0, 0, 200));
    // A linear kinematics' joints are the planner's: motion gives the sink no rates then.
    JointLimitCheck check(trt({}, {}));
    EXPECT_EQ(check.speed_cap_mm_s(c, kAxesFree), INFINITY);
    // Unlimited joints (0) do not cap.
    JointLimitCheck unlimited(trt({0, 0, 0, 0, 0}, {0, 0, 0, 0, 0}));
    EXPECT_EQ(unlimited.speed_cap_mm_s(c, kAxesFree), INFINITY);
}

}  // namespace
