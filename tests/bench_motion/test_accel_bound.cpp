// The acceleration-aware lower bound (accel_bound.hpp) against values worked out by hand from
// the proof in docs/benchmarks.md ("The acceleration-aware lower bound"), and against motions that
// keep the path-distance contract (a lower bound above any of them would be wrong).
#include <gtest/gtest.h>

#include <cmath>

#include "accel_bound.hpp"

namespace motion::bench {
namespace {

constexpr double kV = 100;   // mm/s, every axis
constexpr double kA = 1000;  // mm/s^2, every axis
constexpr double kP = 0.01;  // G64 P, mm
const double kSqrt2 = std::sqrt(2.0);

AxisLimits limits() {
    AxisLimits lim;
    lim.vel_mm_s.fill(kV);
    lim.acc_mm_s2.fill(kA);
    return lim;
}

PathSegment line_to(double x, double y, double z, double feed_mm_s) {
    PathSegment s;
    s.kind = SegmentKind::Line;
    s.end_mm = {x, y, z};
    s.feed_mm_s = feed_mm_s;
    s.rapid = feed_mm_s <= 0;
    s.tolerance_mm = kP;
    return s;
}

// An arc in the XY plane about (cx, cy): turns +1 counter-clockwise (G03), -1 clockwise (G02).
PathSegment arc_to(double x, double y, double cx, double cy, int turns, double feed_mm_s) {
    PathSegment s = line_to(x, y, 0, feed_mm_s);
    s.kind = SegmentKind::Arc;
    s.centre_mm = {cx, cy};
    s.turns = turns;
    return s;
}

BenchProgram program(std::vector<PathSegment> segs) {
    BenchProgram p;
    p.segments = std::move(segs);
    return p;
}

double bound_s(const BenchProgram& p) {
    return accel_lower_bound(p, limits()).time_s;
}

// Rest to rest over d at up to vmax with acc: the bang-bang (triangle or trapezoid) time.
double rest_to_rest_s(double d, double vmax, double acc) {
    if (d <= vmax * vmax / acc) return 2 * std::sqrt(d / acc);
    return 2 * vmax / acc + (d - vmax * vmax / acc) / vmax;
}

TEST(AccelBound, StraightLineFromRestToRestIsTheBangBangTime) {
    // 100 mm at 100 mm/s, 1000 mm/s^2: 0.1 s up (5 mm), 90 mm at 100 mm/s, 0.1 s down = 1.1 s.
    EXPECT_NEAR(bound_s(program({line_to(100, 0, 0, 100)})), 1.1, 1e-12);
    // 4 mm never reaches 100 mm/s: 2 sqrt(4 / 1000) = 0.126491 s.
    EXPECT_NEAR(bound_s(program({line_to(4, 0, 0, 100)})), 2 * std::sqrt(4 / kA), 1e-12);
    // A 45 degree rapid: each axis does 100 mm rest to rest on its own limits, 1.1 s, and the
    // bound along the line (sqrt(2) V, sqrt(2) A) is that exactly.
    EXPECT_NEAR(bound_s(program({line_to(100, 100, 0, 0)})), 1.1, 1e-12);
    // A feed below the axis limit: 100 mm at F1200 (20 mm/s): 0.02 s up, 0.02 s down.
    EXPECT_NEAR(bound_s(program({line_to(100, 0, 0, 20)})), rest_to_rest_s(100, 20, kA), 1e-12);
}

TEST(AccelBound, RightAngleCornerRegionIsTheSquareInsideTheCorner) {
    // X100 then Y100: at the instant the tool passes the corner it is within P of both lines,
    // i.e. in [-P, 0] x [0, P] (plus the disc of radius P about the corner), not within P of it.
    BenchProgram p = program({line_to(100, 0, 0, 100), line_to(100, 100, 0, 100)});
    EXPECT_NEAR(corner_region_support_mm(p, 1, {-1, 0, 0}), kP, 1e-9);
    EXPECT_NEAR(corner_region_support_mm(p, 1, {1, 0, 0}), kP, 1e-9);
    EXPECT_NEAR(corner_region_support_mm(p, 1, {0, 1, 0}), kP, 1e-9);
    EXPECT_NEAR(corner_region_support_mm(p, 1, {0, -1, 0}), kP, 1e-9);
    EXPECT_NEAR(corner_region_support_mm(p, 1, {0, 0, 1}), kP, 1e-9);
    // The inner diagonal reaches the square's far corner (-P, P): sqrt(2) P, where the
    // vertex-distance (Frechet) reading of the tolerance gave P.
    EXPECT_NEAR(corner_region_support_mm(p, 1, {-1 / kSqrt2, 1 / kSqrt2, 0}), kSqrt2 * kP, 1e-9);
    EXPECT_NEAR(corner_region_support_mm(p, 1, {1 / kSqrt2, -1 / kSqrt2, 0}), kP, 1e-9);
    // The program's ends pin the tool to the point.
    EXPECT_EQ(corner_region_support_mm(p, 0, {1, 0, 0}), 0);
    EXPECT_EQ(corner_region_support_mm(p, 2, {1, 0, 0}), 0);
}

TEST(AccelBound, SharpTurnRegionReachesBackAlongBothLines) {
    // X10 then a 135 degree turn towards (-1, 1): within P of both lines the tool can be as far
    // back as x = -(1 + sqrt(2)) P (y = P, on the rhombus where the two strips cross).
    BenchProgram p = program({line_to(10, 0, 0, 100), line_to(5, 5, 0, 100)});
    EXPECT_NEAR(corner_region_support_mm(p, 1, {-1, 0, 0}), (1 + kSqrt2) * kP, 1e-9);
}

TEST(AccelBound, RightAngleCornerIsTwoRampsToSqrt4AP) {
    // X100 Y0 then Y100 at F6000 (100 mm/s), P0.01. Step 1 with d = x: after the corner the path
    // has no extent along +x, the tool is within P of it (+P) and at the corner instant at most P
    // behind it (h(-x) = P), so v_x^2 <= 2A (0 + P + P): v_x <= sqrt(4AP) = 6.3246 mm/s; the
    // same for v_y. Step 2: line 1 covers L + z, line 2 L - z - h(y - x) = L - z - 2P (the square's
    // corner (-P, P) again), each from rest to a corner speed of sqrt(4AP), both cruising at V in
    // between, so the sum does not depend on z:
    //   2 (V / A + (V - c) / A) + (2L - 2P - 2 (V^2 / 2A + (V^2 - c^2) / 2A)) / V.
    double c = std::sqrt(4 * kA * kP), L = 100;
    double ramps_s = 2 * (kV / kA + (kV - c) / kA);
    double ramps_mm = 2 * (kV * kV / (2 * kA) + (kV * kV - c * c) / (2 * kA));
    double hand = ramps_s + (2 * L - 2 * kP - ramps_mm) / kV;  // 2.1875509 s
    double b = bound_s(program({line_to(100, 0, 0, 100), line_to(100, 100, 0, 100)}));
    // The dynamic programme over the offset takes each cell's worst end: at most one cell
    // (2P / 24) at 100 mm/s below the exact minimum.
    EXPECT_LE(b, hand + 1e-9);
    EXPECT_GE(b, hand - 2 * kP / 24 / kV - 1e-9);
    // A corner speed of sqrt(2) times the bound's (the old parabola's ends) would be 0.016 s
    // faster, and so would a skew of sqrt(2) P instead of 2P by 59 microseconds: the bound
    // tells them apart.
    EXPECT_NEAR(hand, 2.1875509, 1e-7);
}

TEST(AccelBound, HairpinCanBeTurnedAnywhereOnTheOverlap) {
    // X10 then back to X5: both moves lie on the same line, so the corner region is the whole
    // overlap and a tool that goes 0 -> 5 and stops keeps the path-distance contract (within P
    // of the first move, then of the second, passing through the corner region at x = 5). Its
    // time, 2 sqrt(5 / A), is an upper limit for any sound lower bound; the vertex reading
    // (turn at x = 10) would give about 0.34 s.
    double b = bound_s(program({line_to(10, 0, 0, 100), line_to(5, 0, 0, 100)}));
    EXPECT_LE(b, 2 * std::sqrt(5 / kA) + 1e-12);
    EXPECT_GT(b, 0.09);  // at least the 4.99 mm of the first move it must cover
    EXPECT_NEAR(corner_region_support_mm(program({line_to(10, 0, 0, 100), line_to(5, 0, 0, 100)}),
                                         1, {-1, 0, 0}),
                5 + kP, 1e-6);
}

TEST(AccelBound, CrossingMovesDoNotWidenTheCornerRegion) {
    // A rapid from (10, 20) to (0, 0), then the full circle about (20, 0) through (0, 0): the
    // rapid crosses the circle again at (8, 16), but the tool hands over through the corner, so
    // the region stays near (0, 0): without that, (8, 16) would count and give h(x) >= 8,
    // h(y) >= 16. The turn is 153 degrees (down the rapid, then up the circle), so the region
    // does reach back along y a few P (the strips cross at 27 degrees: P / sin(13.3 deg) = 4.3 P).
    BenchProgram p =
        program({line_to(10, 20, 0, 0), line_to(0, 0, 0, 0), arc_to(0, 0, 20, 0, -1, 5)});
    EXPECT_LT(corner_region_support_mm(p, 2, {1, 0, 0}), 3 * kP);
    EXPECT_LT(corner_region_support_mm(p, 2, {0, 1, 0}), 5 * kP);
    EXPECT_GT(corner_region_support_mm(p, 2, {0, 1, 0}), 4 * kP);
}

TEST(AccelBound, SemicircleFromRestCoversItsLengthAtTheInnerRadius) {
    // G3 from (0, 0) about (10, 0) to (20, 0) at F1200 (20 mm/s). The tool starts and ends at the
    // programmed points, stays at least r - P from the centre and turns half a turn, so its
    // in-plane path is at least (r - P) pi, at up to 20 mm/s and sqrt(2) A; turning round an
    // axis at the top (rise and fall by 10 (1 - cos a) - 2P) takes less than the feed does at
    // 20 mm/s, so no window adds time.
    double d = (10 - kP) * std::acos(-1.0);
    double acc = kSqrt2 * kA;
    double hand = 2 * 20 / acc + (d - 20 * 20 / acc) / 20;
    double b = bound_s(program({arc_to(20, 0, 10, 0, 1, 20)}));
    EXPECT_NEAR(b, hand, 1e-9);
}

TEST(AccelBound, FullCircleCanBeSkippedUnderThePathDistanceContract) {
    // A full circle starts and ends at the same point: a tool that stays there is within P of
    // the circle all the time and passes both ends' regions in order, so nothing forces it round
    // and a sound bound is 0. A semicircle cannot be skipped (its ends are apart).
    EXPECT_EQ(bound_s(program({arc_to(0, 0, 10, 0, -1, 20)})), 0);
    EXPECT_GT(bound_s(program({arc_to(20, 0, 10, 0, -1, 20)})), 1.5);
}

}  // namespace
}  // namespace motion::bench
