// Planner behaviour on hand-built programs whose answers are computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "motion/planner.hpp"
#include "program_gen.hpp"

namespace motion {
namespace {

PlannerConfig uniform(double v, double a, double j) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(v);
    cfg.limits.acc_mm_s2.fill(a);
    cfg.limits.jerk_mm_s3.fill(j);
    return cfg;
}

PathSegment line_to(AxisArray end, double feed, double tol = 0, int line = 0) {
    PathSegment s;
    s.end_mm = end;
    s.feed_mm_s = feed;
    s.tolerance_mm = tol;
    s.line = line;
    return s;
}

std::vector<PreparedSegment> plan(const PlannerConfig& cfg, const std::vector<PathSegment>& segs,
                                  AxisArray start = {}) {
    Planner p(cfg, start);
    std::vector<PreparedSegment> out;
    PreparedSegment r;
    for (const auto& s : segs) {
        p.push(s);
        while (p.pop(r)) out.push_back(r);
    }
    p.finish();
    while (p.pop(r)) out.push_back(r);
    return out;
}

double total_time(const std::vector<PreparedSegment>& recs) {
    double t = 0;
    for (const auto& r : recs) t += r.profile.duration_s;
    return t;
}

TEST(Planner, SingleLineIsATrapezoidAtTheUsableAcceleration) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    // Along X only, the path may use (1 - reserve) of X's acceleration.
    auto recs = plan(cfg, {line_to({100}, 50)});
    ASSERT_EQ(recs.size(), 1u);
    double a = 1000 * (1 - cfg.override_reserve);
    EXPECT_NEAR(total_time(recs), 100.0 / 50 + 50 / a, 1e-9);
    EXPECT_TRUE(recs.back().program_end);
}

TEST(Planner, DiagonalMoveIsLimitedByTheProjectedAxisLimits) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    // A 3-4-5 move: X takes 0.6 of the path speed, Y 0.8; Y's 100 mm/s caps the path at 125.
    auto recs = plan(cfg, {[] {
                         PathSegment s;
                         s.end_mm = {300, 400};
                         s.rapid = true;
                         return s;
                     }()});
    EXPECT_NEAR(recs[0].profile.peak_v_mm_s, 125, 1e-9);
}

TEST(Planner, ShortSegmentsAreFollowedAtFullFeed) {
    // 5000 collinear moves of 0.01 mm at 50 mm/s: each is a fifth of one 1 ms period's travel.
    PlannerConfig cfg = uniform(100, 1000, 0);
    std::vector<PathSegment> segs;
    for (int i = 1; i <= 5000; ++i)
        segs.push_back(line_to({0.01 * i, 0.001 * std::sin(i * 0.01)}, 50, 0.01, i));
    auto recs = plan(cfg, segs);
    double vmax = 0;
    for (const auto& r : recs) vmax = std::max(vmax, r.profile.peak_v_mm_s);
    EXPECT_NEAR(vmax, 50, 1e-6);
    // 50 mm at 50 mm/s plus one ramp time: no per-segment slowdown.
    EXPECT_LT(total_time(recs), 1.0 + 50 / 900.0 + 0.01);
}

TEST(Planner, JerkLimitedShortSegmentsAlsoReachFullFeed) {
    PlannerConfig cfg = uniform(100, 1000, 1e5);
    std::vector<PathSegment> segs;
    for (int i = 1; i <= 2000; ++i) segs.push_back(line_to({0.05 * i}, 50, 0.01, i));
    auto recs = plan(cfg, segs);
    double vmax = 0;
    for (const auto& r : recs) vmax = std::max(vmax, r.profile.peak_v_mm_s);
    EXPECT_NEAR(vmax, 50, 1e-6);
}

TEST(Planner, JerkLimitedAccelerationRunsOnAcrossShortSegments) {
    // 100 mm as 2000 collinear moves takes as long as one 100 mm move: the S-curve is planned
    // over the run of elements, not restarted from zero acceleration in each 0.05 mm move.
    PlannerConfig cfg = uniform(100, 1000, 1e4);
    std::vector<PathSegment> segs;
    for (int i = 1; i <= 2000; ++i) segs.push_back(line_to({0.05 * i}, 80, 0.01, i));
    double t_split = total_time(plan(cfg, segs));
    double t_whole = total_time(plan(cfg, {line_to({100}, 80)}));
    EXPECT_NEAR(t_split, t_whole, 1e-6 * t_whole);
}

TEST(Planner, ExactPathStopsAtASharpCorner) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    auto recs = plan(cfg, {line_to({10}, 50, 0), line_to({10, 10}, 50, 0)});
    ASSERT_EQ(recs.size(), 2u);  // no blend inserted
    EXPECT_NEAR(recs[0].profile.at(recs[0].profile.duration_s).v_mm_s, 0, 1e-9);
}

TEST(Planner, ExactStopStopsEvenWhenCollinear) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    PathSegment a = line_to({10}, 50, 1);
    a.exact_stop = true;
    auto recs = plan(cfg, {a, line_to({20}, 50, 1)});
    ASSERT_EQ(recs.size(), 2u);
    EXPECT_NEAR(recs[0].profile.at(recs[0].profile.duration_s).v_mm_s, 0, 1e-9);
}

TEST(Planner, CollinearMovesDoNotStop) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    auto recs = plan(cfg, {line_to({10}, 50, 0), line_to({20}, 50, 0)});
    EXPECT_NEAR(recs[0].profile.at(recs[0].profile.duration_s).v_mm_s, 50, 1e-9);
}

TEST(Planner, BlendedRightAngleKeepsSpeedAndStaysWithinTolerance) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    auto recs = plan(cfg, {line_to({10}, 50, tol, 0), line_to({10, 10}, 50, tol, 1)});
    ASSERT_EQ(recs.size(), 3u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Blend);
    // Cut per side: l = tol / ((3/16) |T2 - T1|) with |T2 - T1| = sqrt(2).
    double l = tol / (3.0 / 16.0 * std::sqrt(2.0));
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    // Speed through it: the axis curvature bound 1.5 |dT_k| / 2l with |dT_k| = 1 against the
    // blend's centripetal share (0.95) of the usable acceleration.
    double v = std::sqrt(0.95 * 900 * 2 * l / 1.5);
    EXPECT_NEAR(recs[1].profile.peak_v_mm_s, v, 1e-9);
    // Closest approach to the corner is the tolerance.
    double best = 1e9;
    for (int i = 0; i <= 1000; ++i) {
        MotionSample s = sample(recs[1], recs[1].profile.duration_s * i / 1000);
        best = std::min(best, std::hypot(s.pos_mm[0] - 10, s.pos_mm[1]));
    }
    EXPECT_NEAR(best, tol, 1e-6);
}

TEST(Planner, ArcSpeedRespectsCentripetalAcceleration) {
    // Full circle of radius 5 at F200: v^2 / r within the arc's centripetal share (0.8) of the
    // usable acceleration (900): v = sqrt(0.8 * 900 * 5) = 60 mm/s.
    PlannerConfig cfg = uniform(100, 1000, 0);
    PathSegment arc;
    arc.kind = SegmentKind::Arc;
    arc.end_mm = {10, 0};
    arc.centre_mm = {5, 0};
    arc.feed_mm_s = 200;
    arc.turns = 1;
    auto recs = plan(cfg, {arc}, {10, 0});
    ASSERT_EQ(recs.size(), 1u);
    EXPECT_NEAR(recs[0].profile.peak_v_mm_s, 60, 1e-9);
    for (int i = 0; i <= 2000; ++i) {
        MotionSample s = sample(recs[0], recs[0].profile.duration_s * i / 2000);
        EXPECT_LE(std::fabs(s.acc_mm_s2[0]), 1000 * (1 + 1e-9));
        EXPECT_LE(std::fabs(s.acc_mm_s2[1]), 1000 * (1 + 1e-9));
        EXPECT_NEAR(std::hypot(s.pos_mm[0] - 5, s.pos_mm[1]), 5, 1e-9);
    }
}

TEST(Planner, StreamingWindowGivesTheSamePlanAsOneBigWindow) {
    PlannerConfig big = uniform(100, 1000, 0), small = big;
    small.window = 8;
    std::vector<PathSegment> segs;
    for (int i = 1; i <= 200; ++i) segs.push_back(line_to({double(i), (i % 2) * 0.5}, 80, 0.05, i));
    double t_big = total_time(plan(big, segs)), t_small = total_time(plan(small, segs));
    // A short window may only be slower (it must be able to stop at its end), never faster,
    // and here the look-ahead needed (about 4 mm to brake from 80 mm/s) fits in 8 elements.
    EXPECT_GE(t_small, t_big - 1e-9);
    EXPECT_NEAR(t_small, t_big, 1e-6);
}

TEST(Planner, BadSegmentsNameTheirLineAndChangeNothing) {
    Planner p(uniform(100, 1000, 0), {});
    PathSegment bad = line_to({10}, 0, 0, 17);
    try {
        p.push(bad);
        FAIL();
    } catch (const PlanError& e) {
        EXPECT_EQ(e.line(), 17);
        EXPECT_NE(std::string(e.what()).find("line 17: feed move needs a positive feed rate"),
                  std::string::npos);
    }
    PathSegment nan = line_to({std::nan("")}, 10, 0, 18);
    EXPECT_THROW(p.push(nan), PlanError);
    p.push(line_to({10}, 50, 0, 19));
    p.finish();
    PreparedSegment r;
    ASSERT_TRUE(p.pop(r));
    EXPECT_EQ(r.line, 19);
    EXPECT_EQ(r.geom.origin[0], 0);
    EXPECT_NEAR(r.geom.length_mm, 10, 1e-12);
}

TEST(Planner, ZeroLengthMovesAreDropped) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    auto recs = plan(cfg, {line_to({0}, 50), line_to({10}, 50), line_to({10}, 50)});
    ASSERT_EQ(recs.size(), 1u);
}

TEST(Planner, InvalidConfigIsRejected) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    cfg.limits.acc_mm_s2[4] = 0;
    EXPECT_THROW(Planner(cfg, {}), std::invalid_argument);
    cfg = uniform(100, 1000, -1);
    EXPECT_THROW(Planner(cfg, {}), std::invalid_argument);
}

}  // namespace
}  // namespace motion
