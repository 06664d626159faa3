// The acceleration-aware lower bound (accel_bound.hpp) against values worked out by hand from
// the proof in docs/benchmarks.md ("The acceleration-aware lower bound"), and against motions that
// keep the path-distance contract (a lower bound above any of them would be wrong).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "accel_bound.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "motion/spsc_ring.hpp"

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

TEST(AccelBound, ExactPathCornerIsAStop) {
    // G61 (P = 0): the tool is at rest at the corner, so each line is 1.1 s rest to rest.
    PathSegment a = line_to(100, 0, 0, 100), b = line_to(100, 100, 0, 100);
    a.tolerance_mm = b.tolerance_mm = 0;
    EXPECT_NEAR(bound_s(program({a, b})), 2.2, 1e-12);
}

TEST(AccelBound, CornersCloserThanTheToleranceCostNothing) {
    // X10, a 0.005 mm step in Y, X20: the straight line from (0, 0) to (20, 0.005) is within
    // 0.0025 mm of every move and passes each corner region at (10, 0.0025), so it keeps the
    // contract; its time is X's 20 mm rest to rest, 0.3 s (Y's 0.005 mm takes 4.5 ms). The two
    // right angles must not be charged sqrt(4AP) corner speeds (that would give about 0.39 s).
    double b = bound_s(
        program({line_to(10, 0, 0, 100), line_to(10, 0.005, 0, 100), line_to(20, 0.005, 0, 100)}));
    EXPECT_LE(b, rest_to_rest_s(20, kV, kA) + 1e-12);
    EXPECT_GT(b, rest_to_rest_s(20 - 4 * kP, kV, kA) - 1e-12);
}

TEST(AccelBound, FullCircleCanBeSkippedUnderThePathDistanceContract) {
    // A full circle starts and ends at the same point: a tool that stays there is within P of
    // the circle all the time and passes both ends' regions in order, so nothing forces it round
    // and a sound bound is 0. A semicircle cannot be skipped (its ends are apart).
    EXPECT_EQ(bound_s(program({arc_to(0, 0, 10, 0, -1, 20)})), 0);
    EXPECT_GT(bound_s(program({arc_to(20, 0, 10, 0, -1, 20)})), 1.5);
}

// Distance from (x, y, 0) to a programmed move in the XY plane that starts at `from`.
double distance_to_move(const PathSegment& s, const AxisArray& from, double x, double y) {
    if (s.kind == SegmentKind::Line) {
        double ux = s.end_mm[0] - from[0], uy = s.end_mm[1] - from[1];
        double len2 = ux * ux + uy * uy;
        double t =
            len2 > 0 ? std::clamp(((x - from[0]) * ux + (y - from[1]) * uy) / len2, 0.0, 1.0) : 0;
        return std::hypot(x - from[0] - t * ux, y - from[1] - t * uy);
    }
    const double pi = std::acos(-1.0);
    double cx = s.centre_mm[0], cy = s.centre_mm[1];
    double r = std::hypot(from[0] - cx, from[1] - cy);
    double a0 = std::atan2(from[1] - cy, from[0] - cx),
           a1 = std::atan2(s.end_mm[1] - cy, s.end_mm[0] - cx);
    double sweep = s.turns > 0 ? a1 - a0 : a0 - a1;  // along the arc's direction, in (0, 2 pi]
    while (sweep <= 1e-12) sweep += 2 * pi;
    double ap = std::atan2(y - cy, x - cx);
    double along = s.turns > 0 ? ap - a0 : a0 - ap;
    while (along < 0) along += 2 * pi;
    while (along >= 2 * pi) along -= 2 * pi;
    if (along <= sweep) return std::fabs(std::hypot(x - cx, y - cy) - r);
    return std::min(std::hypot(x - from[0], y - from[1]),
                    std::hypot(x - s.end_mm[0], y - s.end_mm[1]));
}

// A random corner at c = (0, 0) in the XY plane: a line or an arc in, a line or an arc out, at
// any turn (reversals included), of any length down to below P.
BenchProgram random_corner(std::mt19937_64& rng, double& tol) {
    std::uniform_real_distribution<double> u(0, 1);
    const double pi = std::acos(-1.0);
    static const double kTols[] = {0.002, 0.01, 0.05};
    tol = kTols[std::uniform_int_distribution<int>(0, 2)(rng)];
    auto length = [&] { return tol * std::pow(10.0, -0.5 + 3 * u(rng)); };  // 0.3 P .. 300 P
    double h_in = 2 * pi * u(rng);
    double turn = u(rng) < 0.2 ? pi : (u(rng) < 0.5 ? pi / 2 : pi * u(rng));
    double h_out = h_in + (u(rng) < 0.5 ? turn : -turn);
    BenchProgram p;
    PathSegment in, out;
    AxisArray start{};
    if (u(rng) < 0.6) {  // a line ending at (0, 0) along h_in
        double len = length();
        start = {-len * std::cos(h_in), -len * std::sin(h_in), 0};
        in = line_to(0, 0, 0, 100);
    } else {  // an arc ending at (0, 0) with end tangent h_in
        double r = std::max(tol * 2, length()), sweep = (0.05 + 1.8 * u(rng)) * pi;
        int turns = u(rng) < 0.5 ? 1 : -1;
        double side = h_in + turns * pi / 2;  // towards the centre from the end point
        double cx = r * std::cos(side), cy = r * std::sin(side);
        double a1 = std::atan2(-cy, -cx), a0 = a1 - turns * sweep;
        start = {cx + r * std::cos(a0), cy + r * std::sin(a0), 0};
        in = arc_to(0, 0, cx, cy, turns, 100);
    }
    if (u(rng) < 0.6) {
        double len = length();
        out = line_to(len * std::cos(h_out), len * std::sin(h_out), 0, 100);
    } else {
        double r = std::max(tol * 2, length()), sweep = (0.05 + 1.8 * u(rng)) * pi;
        int turns = u(rng) < 0.5 ? 1 : -1;
        double side = h_out + turns * pi / 2;
        double cx = r * std::cos(side), cy = r * std::sin(side);
        double a0 = std::atan2(-cy, -cx), a1 = a0 + turns * sweep;
        out = arc_to(cx + r * std::cos(a1), cy + r * std::sin(a1), cx, cy, turns, 100);
    }
    in.tolerance_mm = out.tolerance_mm = tol;
    p.start_mm = start;
    p.segments = {in, out};
    return p;
}

TEST(AccelBound, CornerRegionSupportHoldsEveryPointOfTheRegion) {
    // Brute force: the grid points (step P / 8, within 40 P of the corner) that are within P of
    // both moves and connected to the corner through such points are a subset of the region,
    // so no direction may find one beyond the support. For two lines the region is convex and
    // the split bound exact, so there the support must also be reached to within the grid.
    const double pi = std::acos(-1.0);
    int tight_checks = 0;
    for (std::uint64_t seed = 1; seed <= 60; ++seed) {
        std::mt19937_64 rng(seed);
        double tol = 0;
        BenchProgram p = random_corner(rng, tol);
        const PathSegment& in = p.segments[0];
        const PathSegment& out = p.segments[1];
        AxisArray c{};
        const int half = 320;
        const double step = tol / 8;
        const int side = 2 * half + 1;
        std::vector<char> inside(side * side, 0), seen(side * side, 0);
        for (int i = 0; i < side; ++i)
            for (int j = 0; j < side; ++j) {
                double x = (i - half) * step, y = (j - half) * step;
                inside[i * side + j] = distance_to_move(in, p.start_mm, x, y) <= tol &&
                                       distance_to_move(out, c, x, y) <= tol;
            }
        std::vector<int> stack{half * side + half}, region;
        seen[half * side + half] = 1;
        while (!stack.empty()) {
            int at = stack.back();
            stack.pop_back();
            region.push_back(at);
            int i = at / side, j = at % side;
            for (auto [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
                int ni = i + di, nj = j + dj;
                if (ni < 0 || nj < 0 || ni >= side || nj >= side) continue;
                int k = ni * side + nj;
                if (!inside[k] || seen[k]) continue;
                seen[k] = 1;
                stack.push_back(k);
            }
        }
        bool lines = in.kind == SegmentKind::Line && out.kind == SegmentKind::Line;
        bool boxed = true;  // the region does not reach the grid's edge
        for (int at : region) {
            int i = at / side, j = at % side;
            boxed = boxed && i > 0 && j > 0 && i < side - 1 && j < side - 1;
        }
        for (int a = 0; a < 16; ++a) {
            double ang = 2 * pi * a / 16 + 0.1;
            std::array<double, 3> d{std::cos(ang), std::sin(ang), 0};
            double best = -1e9;
            for (int at : region)
                best = std::max(
                    best, d[0] * (at / side - half) * step + d[1] * (at % side - half) * step);
            double h = corner_region_support_mm(p, 1, d);
            EXPECT_LE(best, h + 1e-9) << "seed " << seed << " direction " << a;
            if (lines && boxed) {
                EXPECT_LE(h, best + 2 * step) << "seed " << seed << " direction " << a;
                ++tight_checks;
            }
        }
    }
    EXPECT_GT(tight_checks, 200);
}

// Seeded random XYZ programs with the cases the proof has to be careful with: right angles,
// sharp turns and reversals, moves far shorter than P, tangent and kinked arcs, rapids, G09 and
// exact-path corners, mixed tolerances.
BenchProgram random_program(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const double pi = std::acos(-1.0);
    BenchProgram p;
    AxisArray pos{};
    double heading = 2 * pi * u(rng);  // in XY
    int count = 4 + int(10 * u(rng));
    for (int i = 0; i < count; ++i) {
        static const double kTols[] = {0, 0.002, 0.01, 0.01, 0.05, 0.2};
        double tol = kTols[std::uniform_int_distribution<int>(0, 5)(rng)];
        double feed = u(rng) < 0.15 ? 0 : 5 + 145 * u(rng);
        PathSegment s;
        if (u(rng) < 0.25) {  // an arc in XY, tangent or kinked, either way round
            if (u(rng) < 0.5) heading += (u(rng) - 0.5) * pi;
            double r = 0.3 + 15 * u(rng), sweep = (0.1 + 1.7 * u(rng)) * pi;
            int turns = u(rng) < 0.5 ? 1 : -1;
            double side = heading + turns * pi / 2;  // the centre is to the left for G03
            double cx = pos[0] + r * std::cos(side), cy = pos[1] + r * std::sin(side);
            double a0 = std::atan2(pos[1] - cy, pos[0] - cx), a1 = a0 + turns * sweep;
            s.kind = SegmentKind::Arc;
            s.end_mm = pos;
            s.end_mm[0] = cx + r * std::cos(a1);
            s.end_mm[1] = cy + r * std::sin(a1);
            s.centre_mm = {cx, cy};
            s.turns = turns;
            heading = a1 + turns * pi / 2;
        } else {
            static const double kTurns[] = {0, 0.05, 0.3, 0.5, 0.75, 0.9, 1.0};
            double turn = kTurns[std::uniform_int_distribution<int>(0, 6)(rng)] * pi;
            if (u(rng) < 0.3) turn = pi * u(rng);
            heading += u(rng) < 0.5 ? turn : -turn;
            double len = std::pow(10.0, -2.7 + 4.2 * u(rng));  // 0.002 .. 30 mm
            double climb = u(rng) < 0.2 ? (u(rng) - 0.5) * len : 0;
            s.end_mm = pos;
            s.end_mm[0] += len * std::cos(heading);
            s.end_mm[1] += len * std::sin(heading);
            s.end_mm[2] += climb;
        }
        s.feed_mm_s = feed;
        s.rapid = feed == 0;
        s.tolerance_mm = tol;
        s.exact_stop = u(rng) < 0.05;
        s.line = i + 1;
        p.segments.push_back(s);
        pos = s.end_mm;
    }
    return p;
}

// Our planner and sampler keep the contract, so their motion time (whole servo periods until
// done) cannot be below a proven lower bound: if it is, one of the two is wrong. On these seeds
// the closest is 2.4 % above the bound, so this catches gross errors and contract breaks; the
// hand-computed cases above catch the finer ones.
double planner_motion_s(const BenchProgram& prog, const AxisLimits& lim) {
    PlannerConfig cfg;
    cfg.limits = lim;
    Planner planner(cfg, prog.start_mm);
    std::vector<PreparedSegment> recs;
    PreparedSegment rec;
    for (const PathSegment& seg : prog.segments) {
        planner.push(seg);
        while (planner.pop(rec)) recs.push_back(rec);
    }
    planner.finish();
    while (planner.pop(rec)) recs.push_back(rec);
    SpscRing<PreparedSegment> ring(recs.size() + 1);
    for (const auto& r : recs) ring.try_push(r);
    Sampler sampler(sampler_config(cfg), ring, prog.start_mm);
    long periods = 0;
    do {
        sampler.advance(cfg.servo_period_s);
        ++periods;
    } while (!sampler.status().done && periods < 10'000'000);
    return periods * cfg.servo_period_s;
}

TEST(AccelBound, PlannerIsNeverFasterThanTheBoundOnRandomPrograms) {
    int checked = 0;
    for (std::uint64_t seed = 1; seed <= 150; ++seed) {
        std::mt19937_64 rng(seed);
        BenchProgram prog = random_program(rng);
        std::uniform_real_distribution<double> u(0, 1);
        AxisLimits lim;
        for (int k = 0; k < kAxes; ++k) {
            lim.vel_mm_s[k] = 50 + 150 * u(rng);
            lim.acc_mm_s2[k] = 200 + 2800 * u(rng);
        }
        double bound = accel_lower_bound(prog, lim).time_s;
        double ours = planner_motion_s(prog, lim);
        EXPECT_GE(ours, bound - 1e-9) << "seed " << seed;
        checked += bound > 0;
    }
    EXPECT_GT(checked, 140);
}

}  // namespace
}  // namespace motion::bench
