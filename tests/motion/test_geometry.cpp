// Path elements: derivatives against finite differences, end points, blend deviation, errors,
// and the proof that a corner blend with an arc stays within its limit of the programmed path.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include "motion/geometry.hpp"
#include "program_gen.hpp"

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

// The largest distance of the element's in-plane path (X, Y) from the circle about (cu, cv) of
// radius r, sampled.
double off_circle_mm(const Element& e, double cu, double cv, double r) {
    double off = 0;
    for (int k = 0; k <= 1000; ++k) {
        CurvePoint cp;
        evaluate(e, e.length_mm * k / 1000, cp);
        off = std::max(off, std::fabs(std::hypot(cp.p[0] - cu, cp.p[1] - cv) - r));
    }
    return off;
}

// Found by the end-to-end soak (docs/soak.md): a G2 from X100 Y100 about X95 Y100 to
// X100.004 Y100. The only circles through both ends have their centres on x = 100.002; the
// nearest to the programmed centre is a dot of radius 0.002 mm, which the planner ran instead
// of the 31.4 mm circle.
TEST(Geometry, NearlyFullCircleWhoseEndMissesItsStartIsRefusedNotRunAsAnotherCircle) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.line = 3;
    seg.end_mm = {100.004, 100, 0};
    seg.centre_mm = {95, 100};
    seg.turns = -1;
    try {
        const Element e = make_arc({100, 100, 0}, seg);
        FAIL() << "ran as an arc of radius " << e.radius_mm << " mm, " << e.length_mm << " mm long";
    } catch (const PlanError& e) {
        EXPECT_EQ(e.line(), 3);
        const std::string what = e.what();
        EXPECT_NE(what.find("arc end is 0.004000 mm off the circle"), std::string::npos) << what;
        EXPECT_NE(what.find("program the end on the circle"), std::string::npos) << what;
    }
}

// The centre still moves where that keeps the path: a 10 degree arc of radius 5 whose end is
// 0.005 mm outside the circle moves its centre by about r * 0.005 / chord = 0.029 mm, but
// its path stays within 0.01 mm of the programmed circle.
TEST(Geometry, ShortArcWithARoundedEndMovesItsCentreAndKeepsToTheCircle) {
    const double r = 5, a = 10 * std::numbers::pi / 180, out = 0.005;
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.end_mm = {(r + out) * std::cos(a), (r + out) * std::sin(a), 0};
    seg.centre_mm = {0, 0};
    seg.turns = 1;
    const Element e = make_arc({r, 0, 0}, seg);
    EXPECT_GT(std::hypot(e.origin[0], e.origin[1]), 0.02);  // the centre did move
    EXPECT_LE(off_circle_mm(e, 0, 0, r), out + 1e-9);
    EXPECT_NEAR(e.length_mm, r * a, 0.01);
    CurvePoint end;
    evaluate(e, e.length_mm, end);
    EXPECT_EQ(end.p, seg.end_mm);
}

// What the interpreter accepts (ARC_TOLERANCE_MM, 0.01 mm by default) runs: a half circle of
// radius 2 ending 0.008 mm off (the planner refused more than 0.005 mm on small arcs, so
// `cnc check` passed a program `cnc run` then refused).
TEST(Geometry, EndOffTheCircleByWhatTheInterpreterAcceptsRuns) {
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.end_mm = {-2.008, 0, 0};
    seg.centre_mm = {0, 0};
    seg.turns = 1;
    const Element e = make_arc({2, 0, 0}, seg);
    EXPECT_LE(off_circle_mm(e, 0, 0, 2), 0.008 + 1e-9);
    seg.end_mm = {-2.011, 0, 0};
    EXPECT_THROW(make_arc({2, 0, 0}, seg), PlanError);
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

// A random move from `start`: a line, an arc or a helix (in any of the three planes, sometimes
// moving A too), of random length, radius and sweep.
Element random_move(std::mt19937_64& rng, const AxisArray& start, bool arc) {
    std::uniform_real_distribution<double> uni(0, 1);
    std::normal_distribution<double> n(0, 1);
    auto log_uniform = [&](double lo, double hi) {
        return std::exp(std::log(lo) + uni(rng) * (std::log(hi) - std::log(lo)));
    };
    if (!arc) {
        AxisArray end = start, dir{};
        double norm = 0;
        for (int k = 0; k < 4; ++k) dir[k] = k == 3 && uni(rng) < 0.7 ? 0 : n(rng);
        for (double x : dir) norm += x * x;
        double len = log_uniform(0.05, 50);
        for (int k = 0; k < 4; ++k) end[k] += len * dir[k] / std::sqrt(norm);
        return make_line(start, end);
    }
    static constexpr int kPlanes[3][3] = {{0, 1, 2}, {2, 0, 1}, {1, 2, 0}};  // G17, G18, G19
    const int* pl = kPlanes[rng() % 3];
    PathSegment seg;
    seg.kind = SegmentKind::Arc;
    seg.plane_first = pl[0], seg.plane_second = pl[1], seg.plane_normal = pl[2];
    const double r = log_uniform(0.2, 30), th0 = 2 * std::numbers::pi * uni(rng);
    const double sweep = (0.05 + uni(rng) * 1.9) * std::numbers::pi;
    seg.turns = uni(rng) < 0.5 ? 1 : -1;
    seg.centre_mm = {start[pl[0]] - r * std::cos(th0), start[pl[1]] - r * std::sin(th0)};
    const double th1 = th0 + seg.turns * sweep;
    seg.end_mm = start;
    seg.end_mm[pl[0]] = seg.centre_mm[0] + r * std::cos(th1);
    seg.end_mm[pl[1]] = seg.centre_mm[1] + r * std::sin(th1);
    if (uni(rng) < 0.4) seg.end_mm[pl[2]] += r * sweep * n(rng);  // helix
    if (uni(rng) < 0.2) seg.end_mm[3] += 10 * n(rng);             // and a rotary axis
    return make_arc(start, seg);
}

// The planner's longest cut of a move for one corner blend (planner.cpp, max_trim_mm).
double max_cut_mm(const Element& e) {
    return e.kind == ElementKind::Line ? e.length_mm / 2 : 0.45 * e.length_mm;
}

// Distance from p to a point of e near its nearest: 32 samples, then a golden-section search
// between the neighbours of the best one (never below the true distance).
double near_distance_mm(const Element& e, const AxisArray& p) {
    auto at = [&](double s) {
        CurvePoint cp;
        evaluate(e, s, cp);
        return dist(cp.p, p);
    };
    constexpr int kSamples = 32;
    int best = 0;
    double best_d = at(0);
    for (int i = 1; i <= kSamples; ++i) {
        double d = at(e.length_mm * i / kSamples);
        if (d < best_d) best_d = d, best = i;
    }
    const double g = (std::sqrt(5.0) - 1) / 2;
    double lo = e.length_mm * std::max(0, best - 1) / kSamples;
    double hi = e.length_mm * std::min(kSamples, best + 1) / kSamples;
    for (int i = 0; i < 40; ++i) {
        double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
        (at(m1) < at(m2) ? hi : lo) = at(m1) < at(m2) ? m2 : m1;
    }
    return std::min(best_d, at((lo + hi) / 2));
}

// Largest distance of the curve from the two pieces, sampled densely.
double sampled_deviation_mm(const Element& curve, const Element& piece1, const Element& piece2) {
    double worst = 0;
    for (int i = 0; i <= 200; ++i) {
        CurvePoint cp;
        evaluate(curve, curve.length_mm * i / 200, cp);
        double d = near_distance_mm(piece1, cp.p);
        if (d > worst) d = std::min(d, near_distance_mm(piece2, cp.p));
        worst = std::max(worst, d);
    }
    return worst;
}

// Two lines: corner_bezier_points gives the parabola, whose largest distance from the lines is
// (l / 4) sin(angle) (up to 90 degrees), at its middle. The proof is exact there: the middle is
// the first split point and the halves' inner control points are closer to their lines.
TEST(Geometry, CornerBezierProofIsExactForTheParabola) {
    for (double deg : {20.0, 60.0, 90.0}) {
        const double a = deg * std::numbers::pi / 180, l = 0.4;
        const AxisArray t1{1, 0, 0}, t2{std::cos(a), std::sin(a), 0}, corner{5, 5, 1};
        AxisArray p0 = corner, p3 = corner, far = corner;
        for (int k = 0; k < 3; ++k) {
            p0[k] -= l * t1[k], p3[k] += l * t2[k];
            far[k] += 3 * l * t2[k];
        }
        const Element before = make_line({0, 5, 1}, corner), after = make_line(corner, far);
        std::optional<BezierPoints> b = corner_bezier_points(p0, t1, p3, t2, l);
        ASSERT_TRUE(b.has_value());
        const double dev = l / 4 * std::sin(a);
        const CornerPath path = corner_path(before, 2 * l, after, 2 * l, dev);
        EXPECT_TRUE(bezier_within(*b, path, dev * (1 + 1e-9))) << deg;
        EXPECT_FALSE(bezier_within(*b, path, dev * (1 - 1e-6))) << deg;
        const Element curve = make_bezier(b->p0, b->p1, b->p2, b->p3);
        EXPECT_NEAR(sampled_deviation_mm(curve, before, after), dev, 1e-9);
    }
}

// The proof must look at the whole hull, not only at points of the curve: an S-shaped Bezier
// along a straight path, P = (0,0) (1,1) (2,-1) (3,0), crosses the line at its middle but bulges
// by y(u) = 3u (1-u) (1-2u), at most 1 / (2 sqrt 3) at u = 1/2 -+ 1 / sqrt 12.
TEST(Geometry, BezierProofSeesTheBulgeBetweenSplitPoints) {
    const BezierPoints s{{0, 0}, {1, 1}, {2, -1}, {3, 0}};
    const Element before = make_line({-1, 0}, {1.5, 0}), after = make_line({1.5, 0}, {4, 0});
    const double bulge = 1 / (2 * std::sqrt(3.0));
    const CornerPath path = corner_path(before, 2.5, after, 2.5, bulge);
    EXPECT_FALSE(bezier_within(s, path, bulge * (1 - 1e-3)));
    EXPECT_TRUE(bezier_within(s, path, bulge * 1.02));
}

// An arc is proved against chords, which cut inside it by up to their sagitta: a point just
// inside the circle by more than the limit must not pass although it is that close to a chord,
// and points 95 % of the limit inside or outside must pass (the chords' slack is small). The
// path is the last stretch of a quarter circle about the origin that fits 6 chords of 2 %
// slack (planner corners take a few times the tolerance), then a tangent line; the "curve" is
// one point (all four control points equal).
TEST(Geometry, ArcChordsCarryTheirSagittaAsSlack) {
    for (double r : {0.5, 3.0, 20.0}) {
        for (double limit : {0.002, 0.05}) {
            PathSegment seg;
            seg.kind = SegmentKind::Arc;
            seg.turns = 1;
            seg.end_mm = {0, r, 0};
            const Element arc = make_arc({r, 0, 0}, seg);
            const Element line = make_line(arc.end, {-1, r, 0});
            // 2 % slack: r (phi / n)^2 / 8 = 0.02 limit
            const double phi = std::min(std::numbers::pi / 2, 6 * std::sqrt(0.16 * limit / r));
            const CornerPath path = corner_path(arc, r * phi, line, 1, limit);
            int inside_passed = 0, near_failed = 0;
            for (int i = 0; i <= 200; ++i) {
                const double th = std::numbers::pi / 2 - phi * i / 200;
                auto point = [&](double radius) {
                    const AxisArray p{radius * std::cos(th), radius * std::sin(th), 0};
                    return BezierPoints{p, p, p, p};
                };
                inside_passed += bezier_within(point(r - limit * (1 + 1e-6)), path, limit);
                near_failed += !bezier_within(point(r - 0.95 * limit), path, limit);
                near_failed += !bezier_within(point(r + 0.95 * limit), path, limit);
            }
            EXPECT_EQ(inside_passed, 0) << "r " << r << " limit " << limit;
            EXPECT_EQ(near_failed, 0) << "r " << r << " limit " << limit;
        }
    }
}

// What the planner relies on for corners with arcs: a blend that bezier_within accepts never
// leaves the programmed moves by more than the limit (checked by dense sampling), over random
// line-arc, arc-line and arc-arc corners (helices, rotary axes, every plane) and tolerances.
// Each corner is tried with the planner's sequence of cuts, and then pushed to the edge: the
// cut is bisected between the accepted one and the first one tried, and the largest accepted
// is checked too, so that a bound that is too generous shows. And the proof is not much more
// cautious than the truth: it accepts nearly every blend whose sampled distance is clearly
// inside the limit, and the blends at the edge come close to the limit.
TEST(Geometry, ArcCornerBezierAcceptedOnlyWithinTheLimit) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> uni(0, 1);
    int corners = 0, accepted = 0, clearly_inside = 0, clearly_inside_accepted = 0;
    double closest = 0;
    while (corners < 400) {
        AxisArray start{};
        for (int k = 0; k < 3; ++k) start[k] = 20 * (uni(rng) - 0.5);
        const int kinds = 1 + int(rng() % 3);  // 1 line-arc, 2 arc-line, 3 arc-arc
        const Element m1 = random_move(rng, start, kinds & 2);
        const Element m2 = random_move(rng, m1.end, kinds & 1);
        const EndDerivs e1 = end_derivs(m1), s2 = start_derivs(m2);
        double dt2 = 0;
        for (int k = 0; k < kAxes; ++k)
            dt2 += (s2.tangent[k] - e1.tangent[k]) * (s2.tangent[k] - e1.tangent[k]);
        const double sine = corner_sine(dt2);
        if (dt2 < 1e-6 || sine >= 1.35) continue;  // tangent, or stopped at by the planner
        ++corners;
        const double tol = std::exp(std::log(0.002) + uni(rng) * std::log(0.5 / 0.002));
        const double allowed = 0.95 * tol;
        const double l_max = std::min(max_cut_mm(m1), max_cut_mm(m2));
        const double l0 = std::min(l_max, tol / (sine / 4));
        const double reach = std::min(l_max, 2 * l0);
        const CornerPath path = corner_path(m1, reach, m2, reach, allowed);
        const Element piece1 = m1.kind == ElementKind::Line ? trim_line(m1, m1.length_mm - reach, 0)
                                                            : trim_arc(m1, m1.length_mm - reach, 0);
        const Element piece2 = m2.kind == ElementKind::Line ? trim_line(m2, 0, m2.length_mm - reach)
                                                            : trim_arc(m2, 0, m2.length_mm - reach);
        auto blend = [&](double l) {
            CurvePoint a, b;
            evaluate(m1, m1.length_mm - l, a);
            evaluate(m2, l, b);
            return corner_bezier_points(a.p, a.d1, b.p, b.d1, l);
        };
        double l_ok = 0;
        double l = l0;
        for (int attempt = 0; attempt < 12; ++attempt, l *= 0.7) {
            std::optional<BezierPoints> ctrl = blend(l);
            if (!ctrl) continue;
            const bool ok = bezier_within(*ctrl, path, allowed);
            const double dev = sampled_deviation_mm(
                make_bezier(ctrl->p0, ctrl->p1, ctrl->p2, ctrl->p3), piece1, piece2);
            if (dev < 0.9 * allowed) ++clearly_inside, clearly_inside_accepted += ok;
            if (!ok) continue;
            ASSERT_LE(dev, allowed * (1 + 1e-9))
                << "corner " << corners << " attempt " << attempt << " tolerance " << tol;
            ++accepted;
            l_ok = l;
            break;
        }
        if (l_ok == 0 || l_ok == l0) continue;
        double l_bad = l_ok / 0.7;
        for (int step = 0; step < 12; ++step) {
            double mid = (l_ok + l_bad) / 2;
            std::optional<BezierPoints> ctrl = blend(mid);
            (ctrl && bezier_within(*ctrl, path, allowed) ? l_ok : l_bad) = mid;
        }
        const BezierPoints edge = *blend(l_ok);
        const double dev =
            sampled_deviation_mm(make_bezier(edge.p0, edge.p1, edge.p2, edge.p3), piece1, piece2);
        ASSERT_LE(dev, allowed * (1 + 1e-9))
            << "corner " << corners << " at the edge, l " << l_ok << " tolerance " << tol;
        closest = std::max(closest, dev / allowed);
    }
    EXPECT_GE(accepted, corners * 95 / 100);
    EXPECT_GE(clearly_inside_accepted, clearly_inside * 98 / 100);
    EXPECT_GT(closest, 0.98);
}

}  // namespace
}  // namespace motion
