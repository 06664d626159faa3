// Path elements: derivatives against finite differences, end points, blend deviation, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "motion/geometry.hpp"

namespace motion {
namespace {

double dist(const AxisArray& a, const AxisArray& b) {
    double s = 0;
    for (int k = 0; k < kAxes; ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
    return std::sqrt(s);
}

// p', p'' and p''' agree with central differences of the lower derivative, and the bounds hold.
void check_derivatives(const Element& e) {
    ElementBounds b = bounds(e);
    const double h = 1e-6 * std::max(1.0, e.length_mm);
    for (int i = 1; i < 40; ++i) {
        double s = e.length_mm * i / 40;
        CurvePoint lo, mid, hi;
        evaluate(e, s - h, lo);
        evaluate(e, s, mid);
        evaluate(e, s + h, hi);
        for (int k = 0; k < kAxes; ++k) {
            ASSERT_NEAR((hi.p[k] - lo.p[k]) / (2 * h), mid.d1[k], 1e-5) << "axis " << k;
            ASSERT_NEAR((hi.d1[k] - lo.d1[k]) / (2 * h), mid.d2[k],
                        1e-4 * (1 + std::fabs(mid.d2[k])));
            ASSERT_NEAR((hi.d2[k] - lo.d2[k]) / (2 * h), mid.d3[k],
                        1e-4 * (1 + std::fabs(mid.d3[k])));
            ASSERT_LE(std::fabs(mid.d1[k]), b.g1[k] + 1e-12);
            ASSERT_LE(std::fabs(mid.d2[k]), b.g2[k] + 1e-12);
            ASSERT_LE(std::fabs(mid.d3[k]), b.g3[k] + 1e-12);
        }
    }
}

// max(sin(angle), |T2 - T1| / sqrt(2)) for unit tangents with |T2 - T1|^2 = dt2.
double corner_sine(double dt2) {
    double c = 1 - dt2 / 2;
    return std::max(std::sqrt(std::max(0.0, 1 - c * c)), std::sqrt(dt2 / 2));
}

// Distance from p to the corner's two rays (in along -t1 from the corner, out along t2).
double rays_distance(const AxisArray& p, const AxisArray& corner, const AxisArray& t1,
                     const AxisArray& t2) {
    auto ray = [&](const AxisArray& t, double sign) {
        double along = 0;
        for (int k = 0; k < kAxes; ++k) along += (p[k] - corner[k]) * t[k] * sign;
        along = std::max(0.0, along);
        AxisArray foot;
        for (int k = 0; k < kAxes; ++k) foot[k] = corner[k] + sign * along * t[k];
        return dist(p, foot);
    };
    return std::min(ray(t1, -1), ray(t2, 1));
}

// A random corner in four axes: unit tangents in and out, a corner point, a blend length.
struct RandomCorner {
    AxisArray t1{}, t2{}, corner{};
    double l = 0;
    double dt2 = 0;  // |T2 - T1|^2
};
RandomCorner random_corner(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0, 1);
    RandomCorner c;
    double n1 = 0, n2 = 0;
    for (int k = 0; k < 4; ++k) {
        c.t1[k] = n(rng), c.t2[k] = n(rng), c.corner[k] = 10 * n(rng);
        n1 += c.t1[k] * c.t1[k], n2 += c.t2[k] * c.t2[k];
    }
    for (int k = 0; k < 4; ++k) c.t1[k] /= std::sqrt(n1), c.t2[k] /= std::sqrt(n2);
    c.l = 0.05 + std::fabs(n(rng));
    for (int k = 0; k < kAxes; ++k) c.dt2 += (c.t2[k] - c.t1[k]) * (c.t2[k] - c.t1[k]);
    return c;
}

TEST(Geometry, QuarterArcG17HasRightLengthEndsAndUnitSpeed) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.end_mm = {0, 10, 0};
    seg.centre_mm = {0, 0};
    seg.turns = 1;  // counter-clockwise from (10, 0) to (0, 10)
    Element e = make_arc({10, 0, 0}, seg);
    EXPECT_NEAR(e.length_mm, 10 * std::numbers::pi / 2, 1e-12);
    CurvePoint mid;
    evaluate(e, e.length_mm / 2, mid);
    EXPECT_NEAR(mid.p[0], 10 / std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(mid.p[1], 10 / std::sqrt(2.0), 1e-12);
    CurvePoint end;
    evaluate(e, e.length_mm, end);
    EXPECT_EQ(end.p, seg.end_mm);
    check_derivatives(e);
}

TEST(Geometry, ClockwiseArcGoesTheOtherWay) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.end_mm = {0, 10, 0};
    seg.turns = -1;  // clockwise from (10,0) to (0,10): three quarters, through (0,-10)
    Element e = make_arc({10, 0, 0}, seg);
    EXPECT_NEAR(e.length_mm, 10 * 1.5 * std::numbers::pi, 1e-12);
    CurvePoint third;
    evaluate(e, e.length_mm / 3, third);
    EXPECT_NEAR(third.p[1], -10, 1e-9);
}

TEST(Geometry, FullCircleHelixWithExtraTurnsInZXPlane) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.plane_first = 2, seg.plane_second = 0, seg.plane_normal = 1;  // G18
    seg.end_mm = {5, 3, 0, 90};  // back to the same in-plane point, Y and A move
    seg.centre_mm = {0, 0};      // (Z, X)
    seg.turns = 2;
    Element e = make_arc({5, 0, 0}, seg);
    double circle = 2 * std::numbers::pi * 5 * 2;
    EXPECT_NEAR(e.length_mm, std::hypot(circle, std::hypot(3.0, 90.0)), 1e-9);
    check_derivatives(e);
    CurvePoint end;
    evaluate(e, e.length_mm, end);
    EXPECT_EQ(end.p, seg.end_mm);
}

TEST(Geometry, ArcErrorsNameTheLine) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.line = 42;
    seg.end_mm = {0, 12, 0};
    try {
        make_arc({10, 0, 0}, seg);
        FAIL() << "radius mismatch accepted";
    } catch (const PlanError& e) {
        EXPECT_EQ(e.line(), 42);
        EXPECT_NE(std::string(e.what()).find("line 42: arc end is not on the circle"),
                  std::string::npos)
            << e.what();
    }
    seg.end_mm = {1, 1, 0};
    seg.centre_mm = {10, 0};
    EXPECT_THROW(make_arc({10, 0, 0}, seg), PlanError);  // zero radius
    seg.plane_second = 0;
    EXPECT_THROW(make_arc({12, 0, 0}, seg), PlanError);  // bad plane
}

TEST(Geometry, SmallEndRoundingMovesTheCentreOntoTheBisector) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.end_mm = {0, 10.001, 0};  // 1 um off the circle
    Element e = make_arc({10, 0, 0}, seg);
    CurvePoint start;
    evaluate(e, 0, start);
    EXPECT_NEAR(start.p[0], 10, 1e-12);
    CurvePoint near_end;
    evaluate(e, e.length_mm * (1 - 1e-12), near_end);
    EXPECT_LT(dist(near_end.p, seg.end_mm), 1e-9);
}

TEST(Geometry, BlendStaysWithinItsDeviationAndJoinsTangentially) {
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 500; ++trial) {
        const RandomCorner c = random_corner(rng);
        const AxisArray &t1 = c.t1, &t2 = c.t2, &corner = c.corner;
        const double l = c.l;
        Element b = make_blend(corner, t1, t2, l);
        check_derivatives(b);
        double max_dev = 3.0 / 16.0 * l * std::sqrt(c.dt2);
        // What the planner relies on: the distance from the path is at most (3/16) l sin(angle)
        // up to 90 degrees and (3/16) l |T2 - T1| / sqrt(2) beyond.
        double path_dev = 3.0 / 16.0 * l * corner_sine(c.dt2);
        EndDerivs s = start_derivs(b), e = end_derivs(b);
        for (int k = 0; k < kAxes; ++k) {
            EXPECT_NEAR(s.tangent[k], t1[k], 1e-12);
            EXPECT_NEAR(e.tangent[k], t2[k], 1e-12);
            EXPECT_EQ(s.d2[k], 0);
            EXPECT_NEAR(e.d2[k], 0, 1e-15);
        }
        for (int i = 0; i <= 100; ++i) {
            CurvePoint cp;
            evaluate(b, b.length_mm * i / 100, cp);
            ASSERT_LE(rays_distance(cp.p, corner, t1, t2), path_dev + 1e-12);
            double speed = 0;
            for (double x : cp.d1) speed += x * x;
            ASSERT_LE(std::sqrt(speed), 1 + 1e-12);
        }
        CurvePoint mid;
        evaluate(b, l, mid);
        EXPECT_NEAR(dist(mid.p, corner), max_dev, 1e-12);
    }
}

// The planner's corner without a jerk limit: a cubic with the parabola's control points.
TEST(Geometry, ParabolicBezierBlendStaysWithinQuarterLSineAndHasUnitEndSpeed) {
    std::mt19937_64 rng(5);
    for (int trial = 0; trial < 500; ++trial) {
        const RandomCorner c = random_corner(rng);
        const AxisArray &t1 = c.t1, &t2 = c.t2, &corner = c.corner;
        const double l = c.l, dt = c.dt2;
        Element b = make_parabola(corner, t1, t2, l);
        EXPECT_NEAR(b.length_mm, 2 * l, 1e-12);
        check_derivatives(b);
        EndDerivs s = start_derivs(b), e = end_derivs(b);
        for (int k = 0; k < kAxes; ++k) {
            EXPECT_NEAR(s.tangent[k], t1[k], 1e-12);
            EXPECT_NEAR(e.tangent[k], t2[k], 1e-12);
            // constant second derivative: the per-axis bang-bang corner
            EXPECT_NEAR(s.d2[k], (t2[k] - t1[k]) / (2 * l), 1e-9);
            EXPECT_NEAR(e.d2[k], (t2[k] - t1[k]) / (2 * l), 1e-9);
        }
        double worst = 0;
        for (int i = 0; i <= 200; ++i) {
            CurvePoint cp;
            evaluate(b, b.length_mm * i / 200, cp);
            worst = std::max(worst, rays_distance(cp.p, corner, t1, t2));
            double speed = 0;
            for (double x : cp.d1) speed += x * x;
            ASSERT_LE(std::sqrt(speed), 1 + 1e-12);
        }
        EXPECT_LE(worst, l / 4 * corner_sine(dt) + 1e-12);
    }
}

TEST(Geometry, TrimmedHelixFollowsTheOriginal) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.plane_first = 2, seg.plane_second = 0, seg.plane_normal = 1;  // G18
    seg.end_mm = {3, 4, 0, 30};  // Y and A move linearly: a helix with a rotary axis
    seg.centre_mm = {0, 0};      // (Z, X)
    seg.turns = -2;
    Element arc = make_arc({3, 0, 0, 0}, seg);
    const double from = 0.7, to = 1.3;
    Element t = trim_arc(arc, from, to);
    EXPECT_NEAR(t.length_mm, arc.length_mm - from - to, 1e-12);
    for (int i = 0; i <= 50; ++i) {
        double s = t.length_mm * i / 50;
        CurvePoint a, b;
        evaluate(arc, from + s, a);
        evaluate(t, s, b);
        for (int k = 0; k < kAxes; ++k) {
            ASSERT_NEAR(a.p[k], b.p[k], 1e-9) << "s " << s << " axis " << k;
            ASSERT_NEAR(a.d1[k], b.d1[k], 1e-9);
            ASSERT_NEAR(a.d2[k], b.d2[k], 1e-9);
        }
    }
}

}  // namespace
}  // namespace motion
