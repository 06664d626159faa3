// Joint limits of linear kinematics in the planner's limits (limits.hpp): a CoreXY machine
// (joint 0 = X + Y, joint 1 = X - Y) whose motors, not its axes, are the limit. Expected values
// are worked out by hand in the comments: along a unit direction (c, s) in XY motor A turns at
// |c + s| and motor B at |c - s| per unit of path speed.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "motion/geometry.hpp"
#include "motion/kinematics.hpp"
#include "motion/limits.hpp"
#include "motion/probe_jog.hpp"

namespace motion {
namespace {

constexpr double kSqrt2 = std::numbers::sqrt2;

// Axes far looser than the motors: X Y Z at 1000 mm/s and 1e5 mm/s^2, no jerk limit.
AxisLimits loose_axes() {
    AxisLimits lim;
    lim.vel_mm_s.fill(1000);
    lim.acc_mm_s2.fill(1e5);
    return lim;
}

// CoreXY with motors A and B at 100 mm/s and 1000 mm/s^2 (Z's motor as loose as Z).
AxisLimits corexy_limits(double jerk_mm_s3 = 0) {
    AxisLimits lim = loose_axes();
    const std::vector<AxisArray> rows = CoreXYKinematics().linear_map();
    const std::vector<JointLimit> joints = {
        {100, 1000, jerk_mm_s3}, {100, 1000, jerk_mm_s3}, {0, 0, 0}};
    set_linear_joints(lim, rows, joints);
    return lim;
}

AxisArray xy(double x, double y) {
    AxisArray p{};
    p[0] = x, p[1] = y;
    return p;
}

ElementLimits line_limits(double angle_deg, const AxisLimits& lim, double feed = 0) {
    const double a = angle_deg * std::numbers::pi / 180;
    const Element e = make_line(xy(0, 0), xy(10 * std::cos(a), 10 * std::sin(a)));
    return element_limits(e, bounds(e), lim, feed, {});
}

TEST(JointLimits, CoreXYKeepsOnlyTheMotorsTighterThanTheAxes) {
    const AxisLimits lim = corexy_limits();
    ASSERT_EQ(lim.joints.count, 2);  // Z's motor (0 = unlimited) is left out
    EXPECT_EQ(lim.joints.rows[0], xy(1, 1));
    EXPECT_EQ(lim.joints.rows[1], xy(1, -1));
    EXPECT_EQ(lim.joints.vel_mm_s[0], 100);
    EXPECT_EQ(lim.joints.acc_mm_s2[1], 1000);
    EXPECT_EQ(lim.joints.jerk_mm_s3[0], 0);  // neither the motors nor the axes limit jerk
}

TEST(JointLimits, MotorsAsFastAsTheAxesAllowAreLeftOut) {
    // configs/sim/corexy.ini: motors at twice the axes, which is what X + Y can reach anyway.
    AxisLimits lim;
    lim.vel_mm_s.fill(100);
    lim.acc_mm_s2.fill(1000);
    lim.jerk_mm_s3.fill(20000);
    const std::vector<JointLimit> twice(3, JointLimit{200, 2000, 40000});
    set_linear_joints(lim, CoreXYKinematics().linear_map(), twice);
    EXPECT_EQ(lim.joints.count, 0);
    // A gantry whose motors equal the axes, and one with unlimited motors.
    const std::vector<JointLimit> same(4, JointLimit{100, 1000, 20000});
    set_linear_joints(lim, TrivialKinematics("XYYZ").linear_map(), same);
    EXPECT_EQ(lim.joints.count, 0);
    set_linear_joints(lim, TrivialKinematics("XYYZ").linear_map(), std::vector<JointLimit>(4));
    EXPECT_EQ(lim.joints.count, 0);
    // One motor of the gantry's pair slower than Y: that joint alone is kept, as Y's row.
    std::vector<JointLimit> slow = same;
    slow[2].vel_mm_s = 80;
    set_linear_joints(lim, TrivialKinematics("XYYZ").linear_map(), slow);
    ASSERT_EQ(lim.joints.count, 1);
    EXPECT_EQ(lim.joints.rows[0], xy(0, 1));
    EXPECT_EQ(lim.joints.vel_mm_s[0], 80);
    EXPECT_EQ(lim.joints.acc_mm_s2[0], 1000);
}

TEST(JointLimits, BadJointLimitsAreRefused) {
    AxisLimits lim = loose_axes();
    const std::vector<AxisArray> rows = CoreXYKinematics().linear_map();
    EXPECT_THROW(set_linear_joints(lim, rows, std::vector<JointLimit>(2)), std::invalid_argument);
    EXPECT_THROW(set_linear_joints(lim, rows, std::vector<JointLimit>(3, JointLimit{-1, 0, 0})),
                 std::invalid_argument);
    EXPECT_THROW(set_linear_joints(lim, rows, std::vector<JointLimit>(3, JointLimit{NAN, 0, 0})),
                 std::invalid_argument);
    JointLimits bad;
    bad.count = 1;
    bad.vel_mm_s[0] = 1;  // acceleration 0
    EXPECT_THROW(validate_joints(bad), std::invalid_argument);
}

TEST(JointLimits, LinearMapsAreTheInverseKinematics) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-100, 100);
    const CoreXYKinematics corexy;
    const TrivialKinematics gantry("XYYZA");
    for (const Kinematics* k :
         {static_cast<const Kinematics*>(&corexy), static_cast<const Kinematics*>(&gantry)}) {
        const std::vector<AxisArray> rows = k->linear_map();
        ASSERT_EQ(rows.size(), k->joint_count()) << k->name();
        for (int n = 0; n < 20; ++n) {
            AxisArray p;
            for (double& x : p) x = u(rng);
            std::vector<double> q(k->joint_count());
            k->inverse(p, q);
            for (std::size_t j = 0; j < q.size(); ++j) {
                double mq = 0;
                for (int a = 0; a < kAxes; ++a) mq += rows[j][a] * p[a];
                EXPECT_DOUBLE_EQ(mq, q[j]) << k->name() << " joint " << j;
            }
        }
    }
    EXPECT_TRUE(XyzacTrtKinematics(TrtPivots{}).linear_map().empty());
}

TEST(JointLimits, AnXLineRunsAtTheMotorLimits) {
    // Along X both motors turn at the path speed: 100 mm/s, 1000 mm/s^2.
    const ElementLimits l = line_limits(0, corexy_limits());
    EXPECT_DOUBLE_EQ(l.vcap_mm_s, 100);
    EXPECT_DOUBLE_EQ(l.tangent.acc_mm_s2, 1000);
}

TEST(JointLimits, ADiagonalLineRunsAtTheMotorLimitsOverSqrt2) {
    // At 45 degrees motor A turns at sqrt(2) times the path speed, B stands still.
    const ElementLimits l = line_limits(45, corexy_limits());
    EXPECT_NEAR(l.vcap_mm_s, 100 / kSqrt2, 1e-9);  // 70.7107
    EXPECT_NEAR(l.tangent.acc_mm_s2, 1000 / kSqrt2, 1e-9);
    // Without the motors' limits the axes (1000 mm/s) would allow 1000 / cos 45.
    EXPECT_NEAR(line_limits(45, loose_axes()).vcap_mm_s, 1000 * kSqrt2, 1e-9);
}

TEST(JointLimits, ALineAt30DegreesIsBoundByMotorA) {
    // cos 30 + sin 30 = 1.3660 for A, cos 30 - sin 30 = 0.3660 for B.
    const double a_rate = std::cos(std::numbers::pi / 6) + 0.5;
    const ElementLimits l = line_limits(30, corexy_limits());
    EXPECT_NEAR(l.vcap_mm_s, 100 / a_rate, 1e-9);  // 73.2051
    EXPECT_NEAR(l.tangent.acc_mm_s2, 1000 / a_rate, 1e-9);
    // A feed below that wins.
    EXPECT_DOUBLE_EQ(line_limits(30, corexy_limits(), 50).vcap_mm_s, 50);
}

TEST(JointLimits, OnACircleBothMotorsSeeSqrt2TimesAnAxis) {
    // On a circle in XY the motors' in-plane amplitudes are |M u| = |M w| = sqrt(2) for the
    // unit vectors u, w of the plane, so motor j sees exactly what an axis sees with sqrt(2)
    // times the motion: CoreXY at 100 / 1000 equals a plain machine at 100 / sqrt 2 and
    // 1000 / sqrt 2.
    PathSegment arc;
    arc.kind = SegmentKind::Arc;
    arc.end_mm = xy(1, 0);  // full circle of radius 1 about the origin, from (1, 0)
    arc.centre_mm = {0, 0};
    const Element e = make_arc(xy(1, 0), arc);
    AxisLimits plain = loose_axes();
    plain.vel_mm_s[0] = plain.vel_mm_s[1] = 100 / kSqrt2;
    plain.acc_mm_s2[0] = plain.acc_mm_s2[1] = 1000 / kSqrt2;
    const ElementLimits c = element_limits(e, bounds(e), corexy_limits(), 0, {});
    const ElementLimits p = element_limits(e, bounds(e), plain, 0, {});
    EXPECT_NEAR(c.vcap_mm_s, p.vcap_mm_s, 1e-9);
    EXPECT_NEAR(c.tangent.acc_mm_s2, p.tangent.acc_mm_s2, 1e-9);
    // By hand: without a jerk limit an arc may turn on 95 % of the acceleration, so
    // v^2 sqrt(2) / R = 0.95 x 1000 at R = 1: v = 25.918 mm/s (velocity would allow 70.7), and
    // the tangential part then fits in quadrature: sqrt((a sqrt 2)^2 + 950^2) = 1000 gives
    // a = sqrt(97500 / 2) = 220.79 mm/s^2.
    EXPECT_NEAR(c.vcap_mm_s, std::sqrt(0.95 * 1000 / kSqrt2), 1e-9);
    EXPECT_NEAR(c.tangent.acc_mm_s2, std::sqrt(97500.0 / 2), 1e-6);
}

TEST(JointLimits, JointJerkLimitsTheTangentialJerkOfALine) {
    // 45 degrees: motor A's jerk is sqrt(2) times the path's, so 20000 mm/s^3 allows
    // 20000 / sqrt 2 along the path.
    const AxisLimits lim = corexy_limits(20000);
    EXPECT_TRUE(jerk_limited(lim));
    EXPECT_FALSE(jerk_limited(corexy_limits()));
    const ElementLimits l = line_limits(45, lim);
    EXPECT_NEAR(l.tangent.jerk_mm_s3, 20000 / kSqrt2, 1e-6);
}

TEST(JointLimits, ExactJointBoundsOfALineAndConservativeOnesFromAxisBounds) {
    const AxisLimits lim = corexy_limits();
    const Element e = make_line(xy(0, 0), xy(3, 1));  // 18.43 degrees
    const double c = 3 / std::sqrt(10.0), s = 1 / std::sqrt(10.0);
    const ElementBounds exact = joint_bounds(e, lim.joints);
    ASSERT_EQ(exact.axis_count, 2);
    EXPECT_NEAR(exact.g1[0], c + s, 1e-15);
    EXPECT_NEAR(exact.g1[1], c - s, 1e-15);
    // From the axis bounds alone each motor gets |c| + |s|: right for A, too much for B.
    const ElementBounds summed = joint_bounds(bounds(e), lim.joints);
    EXPECT_NEAR(summed.g1[0], c + s, 1e-15);
    EXPECT_NEAR(summed.g1[1], c + s, 1e-15);
}

TEST(JointLimits, ParabolaCutForARightAngleUsesMotorB) {
    // +X onto +Y: dT = (-1, 1); motor A sees 0, motor B |-1 - 1| = 2. The parabola's second
    // derivative is dT / 2l, so at speed v motor B needs v^2 2 / 2l <= 0.95 x 1000 (the blend's
    // default turning share): l = v^2 / 950, 0.10526 mm at 10 mm/s.
    AxisArray dt = xy(-1, 1);
    EXPECT_NEAR(parabola_cut_for_speed_mm(dt, 10, corexy_limits(), {}), 100.0 / 950, 1e-12);
    // A turn from +X onto the diagonal (1, 1) / sqrt 2 moves motor B by 1 (0 - 1) and motor A
    // by sqrt 2 - 1: B again.
    dt = xy(1 / kSqrt2 - 1, 1 / kSqrt2);
    EXPECT_NEAR(parabola_cut_for_speed_mm(dt, 10, corexy_limits(), {}), 100.0 / 950 / 2, 1e-12);
}

TEST(JointLimits, RateCapCountsTheMotors) {
    const AxisLimits lim = corexy_limits();
    const Element x_line = make_line(xy(0, 0), xy(10, 0));
    // X line at 90 mm/s: the motors allow 100 / 90 = 1.111 times faster.
    EXPECT_NEAR(rate_cap(bounds(x_line), lim, 90, 0, 0, {}, 1.2), 100.0 / 90, 1e-12);
    EXPECT_DOUBLE_EQ(rate_cap(bounds(x_line), lim, 50, 0, 0, {}, 1.2), 1.2);
    // Diagonal at 60 mm/s: motor A at 60 sqrt 2 = 84.85 allows 1.1785.
    const Element diag = make_line(xy(0, 0), xy(10, 10));
    EXPECT_NEAR(rate_cap(bounds(diag), lim, 60, 0, 0, {}, 1.2), 100 / (60 * kSqrt2), 1e-12);
    // Accelerating at 700 mm/s^2 there: motor A at 989.9 of 1000: r^2 <= 1.0102.
    EXPECT_NEAR(rate_cap(bounds(diag), lim, 10, 700, 0, {}, 1.2), std::sqrt(1000 / (700 * kSqrt2)),
                1e-12);
}

TEST(JointLimits, PassSpeedOfARightAngle) {
    // +X then +Y: each motor turns at 1 per unit of path speed on both sides.
    EXPECT_DOUBLE_EQ(pass_speed_cap(xy(1, 0), xy(0, 1), corexy_limits(), 500), 100);
    // The diagonal then -X: motor A at sqrt 2 before the corner.
    EXPECT_NEAR(pass_speed_cap(xy(1 / kSqrt2, 1 / kSqrt2), xy(-1, 0), corexy_limits(), 500),
                100 / kSqrt2, 1e-12);
    EXPECT_DOUBLE_EQ(pass_speed_cap(xy(1, 0), xy(0, 1), loose_axes(), 500), 500);
}

// The probe's conditional move (G904) moves each axis on its own. Probing X and Y at once at
// 500 mm/s each (both inputs never come): X + Y could ask 2 x 1000 mm/s and 2 x 1e5 mm/s^2 of
// motor A, so each axis gets 100 / 2000 of its velocity and 1000 / 2e5 of its acceleration:
// 50 mm/s and 500 mm/s^2, motor A at 100 and 1000. X alone gets 100 / 1000: 100 mm/s.
TEST(JointLimits, ProbeMovesShareTheMotorsBetweenTheirAxes) {
    const AxisLimits lim = corexy_limits();
    auto run = [&](bool with_y, double& peak_x, double& peak_a, double& peak_acc_a) {
        std::array<ProbeAxis, kProbeAxes> axes{};
        axes[0] = {0, true, 500, 50};
        if (with_y) axes[1] = {1, true, 500, 50};
        ProbeJog jog;
        jog.start(AxisArray{}, axes, lim);
        peak_x = peak_a = peak_acc_a = 0;
        double prev_a = 0;
        for (int n = 0; n < 10000 && !jog.finished(); ++n) {
            jog.step(1e-3, 0, 1.0);
            const double va = joint_component(lim.joints, 0, jog.vel_mm_s());
            peak_x = std::max(peak_x, std::fabs(jog.vel_mm_s()[0]));
            peak_a = std::max(peak_a, std::fabs(va));
            peak_acc_a = std::max(peak_acc_a, std::fabs(va - prev_a) / 1e-3);
            prev_a = va;
        }
        EXPECT_TRUE(jog.finished());
        EXPECT_NEAR(jog.pos_mm()[0], 50, 1e-9);
    };
    double peak_x, peak_a, peak_acc_a;
    run(true, peak_x, peak_a, peak_acc_a);
    EXPECT_NEAR(peak_x, 50, 1e-9);
    EXPECT_NEAR(peak_a, 100, 1e-9);
    EXPECT_LE(peak_acc_a, 1000 * (1 + 1e-9));
    run(false, peak_x, peak_a, peak_acc_a);
    EXPECT_NEAR(peak_x, 100, 1e-9);
    EXPECT_NEAR(peak_a, 100, 1e-9);
    EXPECT_LE(peak_acc_a, 1000 * (1 + 1e-9));
    // Without joints nothing is shared.
    const IndependentShares none = independent_axes_shares(loose_axes(), {true, true});
    EXPECT_EQ(none.vel, 1);
    EXPECT_EQ(none.acc, 1);
}

TEST(JointLimits, IdentityRowsAtTheAxisLimitsChangeNothing) {
    // Rows that repeat the axes with the axes' own limits (listed by hand: set_linear_joints
    // would leave them out) give the same numbers bit for bit, on every element kind.
    AxisLimits lim;
    lim.vel_mm_s.fill(80);
    lim.acc_mm_s2.fill(900);
    lim.jerk_mm_s3.fill(15000);
    AxisLimits with = lim;
    with.joints.count = 3;
    for (int j = 0; j < 3; ++j) {
        with.joints.rows[j][j] = 1;
        with.joints.vel_mm_s[j] = 80;
        with.joints.acc_mm_s2[j] = 900;
        with.joints.jerk_mm_s3[j] = 15000;
    }
    PathSegment arc;
    arc.kind = SegmentKind::Arc;
    arc.end_mm = xy(0, 5);
    arc.end_mm[2] = 2;  // a quarter helix
    arc.centre_mm = {0, 0};
    AxisArray c{};
    c[0] = 5;
    const std::vector<Element> elems = {make_line(xy(0, 0), xy(3, 7)), make_arc(c, arc),
                                        make_blend(xy(1, 1), xy(1, 0), xy(0, 1), 0.5),
                                        make_bezier(xy(0, 0), xy(1, 0), xy(2, 1), xy(2, 2))};
    for (const Element& e : elems) {
        const ElementBounds b = bounds(e);
        for (double feed : {0.0, 30.0}) {
            const ElementLimits a = element_limits(e, b, lim, feed, {0.99, 0.99, 0});
            const ElementLimits j = element_limits(e, b, with, feed, {0.99, 0.99, 0});
            EXPECT_EQ(a.vcap_mm_s, j.vcap_mm_s) << int(e.kind);
            EXPECT_EQ(a.tangent.acc_mm_s2, j.tangent.acc_mm_s2) << int(e.kind);
            EXPECT_EQ(a.tangent.jerk_mm_s3, j.tangent.jerk_mm_s3) << int(e.kind);
        }
        EXPECT_EQ(rate_cap(b, lim, 40, 300, 5000, {0.99, 0.99}, 1.2),
                  rate_cap(b, with, 40, 300, 5000, {0.99, 0.99}, 1.2));
    }
}

}  // namespace
}  // namespace motion
