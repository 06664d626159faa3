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
    double a = 1000 * (1 - override_reserve_in_effect(cfg));
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

// Largest distance of a record's path from the corner (10, 0) of the lines (0,0)-(10,0)-(10,10).
double right_angle_deviation(const PreparedSegment& rec) {
    double worst = 0;
    for (int i = 0; i <= 2000; ++i) {
        MotionSample s = sample(rec, rec.profile.duration_s * i / 2000);
        double to_first = s.pos_mm[0] <= 10 ? std::fabs(s.pos_mm[1]) : 1e9;
        double to_second = s.pos_mm[1] >= 0 ? std::fabs(s.pos_mm[0] - 10) : 1e9;
        worst = std::max(worst, std::min(to_first, to_second));
    }
    return worst;
}

// Without a jerk limit a right angle between long lines is cut on the lines moved d = 0.99 tol
// outwards (offset_corner): the parabola between them may lie 2 x 0.99 tol from them, so it cuts
// lp = 4 (2 x 0.99 tol) / sin(90 deg) from each, and its middle is 0.99 tol inside the corner.
// Shifts of ls = 3 v sqrt(6 d / (0.5 A)) (v = sqrt(2 lp A), the corner's speed at the full
// acceleration A = 1000) move the tool onto the offset lines and back.
TEST(Planner, BlendedRightAngleIsCutOnOffsetLinesWithoutJerkLimit) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    auto recs = plan(cfg, {line_to({10}, 50, tol, 0), line_to({10, 10}, 50, tol, 1)});
    ASSERT_EQ(recs.size(), 5u);
    for (int i = 1; i <= 3; ++i) ASSERT_EQ(recs[i].geom.kind, ElementKind::Bezier) << i;
    // The first shift runs along the first move; the turn belongs to the next, as blends do.
    EXPECT_EQ(recs[1].line, 0);
    EXPECT_EQ(recs[2].line, 1);
    EXPECT_EQ(recs[3].line, 1);
    const double d = 0.99 * tol, lp = 4 * 2 * 0.99 * tol;
    const double ls = 3 * std::sqrt(2 * lp * 1000) * std::sqrt(6 * d / (0.5 * 1000));
    // Each line loses lp + ls less d tan(45 deg): the offset corner is d outside both lines.
    EXPECT_NEAR(recs[0].geom.length_mm, 10 - (lp + ls - d), 1e-12);
    EXPECT_NEAR(recs[4].geom.length_mm, 10 - (lp + ls - d), 1e-12);
    EXPECT_NEAR(recs[2].geom.length_mm, 2 * lp, 1e-12);
    // The corner turns with 0.99 of the usable 990 mm/s^2 (both shifts can change the speed):
    // sqrt(2) x the 8.855 mm/s of the parabola cut only inside the corner.
    const double v = std::sqrt(0.99 * 990 * 2 * lp);
    EXPECT_NEAR(recs[2].profile.peak_v_mm_s, v, 1e-9);
    EXPECT_NEAR(v, std::sqrt(2.0) * std::sqrt(0.99 * 990 * 0.08) * std::sqrt(0.99), 1e-9);
    MotionSample mid = sample(recs[2], recs[2].profile.duration_s / 2);
    EXPECT_NEAR(mid.acc_mm_s2[0], -0.99 * 990, 1e-6);
    EXPECT_NEAR(mid.acc_mm_s2[1], 0.99 * 990, 1e-6);
    // 0.99 tol outside along the first shift, 0.99 tol inside at the corner's middle, never
    // in the quadrant beyond the corner (right_angle_deviation counts that as 1e9).
    EXPECT_NEAR(right_angle_deviation(recs[1]), d, 1e-6);
    EXPECT_NEAR(right_angle_deviation(recs[2]), 0.99 * tol, 1e-6);
    EXPECT_NEAR(right_angle_deviation(recs[3]), d, 1e-6);
    EXPECT_NEAR(std::hypot(mid.pos_mm[0] - 10 + 0.99 * tol, mid.pos_mm[1] - 0.99 * tol), 0, 1e-9);
}

// Where the lines leave no room for the shifts the corner is the parabola cut inside it, from
// l = 4 tol before to l after the corner, with pseudo length 2 l. (A one-sided offset corner
// would need a shift of at least 2 x its turn's speed, 2 x 3 x 10.6 mm/s x sqrt(6 x 0.0099 /
// (0.5 x 1000)) / 3 = 0.23 mm, on a line that keeps 0.2 - 0.056 mm.)
TEST(Planner, BlendedRightAngleBetweenShortLinesIsTheParabolaWithoutJerkLimit) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    auto recs = plan(cfg, {line_to({0.2}, 50, tol, 0), line_to({0.2, 0.2}, 50, tol, 1)});
    ASSERT_EQ(recs.size(), 3u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    double l = 4 * tol;
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    EXPECT_NEAR(recs[0].geom.length_mm, 0.2 - l, 1e-12);
    // Constant acceleration |dT_k| / 2l v^2 per axis; the lines keep more than 2l, so the
    // blend is isolated and turns with 0.99 of the usable 990 mm/s^2: 8.855 mm/s.
    double v = std::sqrt(0.99 * 990 * 2 * l);
    EXPECT_NEAR(recs[1].profile.peak_v_mm_s, v, 1e-9);
    MotionSample mid = sample(recs[1], recs[1].profile.duration_s / 2);
    EXPECT_NEAR(mid.acc_mm_s2[0], -0.99 * 990, 1e-6);
    EXPECT_NEAR(mid.acc_mm_s2[1], 0.99 * 990, 1e-6);
}

// In a zigzag of 0.1 mm moves the 90 degree blends (l = 4 tol = 0.04 mm) leave 0.02 mm of each
// move: the blends must change speed themselves and keep 5 % of the acceleration for it, so
// they turn with 0.95 of it, v = sqrt(0.95 * 990 * 0.08) = 8.674 mm/s.
TEST(Planner, BlendsInAChainOfShortMovesKeepAShareForSpeedChanges) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    std::vector<PathSegment> segs;
    for (int i = 1; i <= 40; ++i)
        segs.push_back(line_to({0.1 * ((i + 1) / 2), 0.1 * (i / 2)}, 50, tol, i));
    auto recs = plan(cfg, segs);
    double v = std::sqrt(0.95 * 990 * 2 * 4 * tol);
    int blends = 0;
    for (const auto& r : recs) {
        if (r.geom.kind != ElementKind::Bezier) continue;
        ++blends;
        EXPECT_NEAR(r.geom.length_mm, 8 * tol, 1e-12);
        EXPECT_LE(r.profile.peak_v_mm_s, v * (1 + 1e-12));
    }
    EXPECT_EQ(blends, 39);
    // The middle of the zigzag runs at that speed.
    EXPECT_NEAR(recs[recs.size() / 2].profile.peak_v_mm_s, v, 1e-9);
}

// A right angle from a long line onto a 0.25 mm one (which continues straight on): the short
// line has no room for the lane change back (offset_corner needs >= 0.27 mm of it beyond the
// turn; a line of at most 1 mm gives it 0.9 of itself, 0.225 mm here; with 0.5 mm, as this test
// had until 2026-11-22, it now gets the offset corner), so only the long line is moved
// outwards, by d = 0.99 tol (one_sided_offset_corner).
// Turning from +X onto +Y at (10, 0), the offset line y = -d meets x = 10 at c2 = (10, -d), and
// the parabola runs from (10 - lp, -d) to (10, lp - d): its distance from the lines is
// min(u^2 lp - d, lp (1 - u)^2), largest where the two are equal, (lp - d)^2 / (4 lp). That is
// P' = 0.995 tol (the proof's limit) for lp = (sqrt(P' + d) + sqrt(P'))^2 = 5.79 tol; the cut
// taken is 0.995 x that, 1.44 x the inside parabola's 4 tol, whose distance is 0.988 tol. The
// shift is cut as offset_corner's: 3 x the turn's speed sqrt(2 lp A) on half the acceleration.
TEST(Planner, RightAngleOntoAShortLineIsCutOnTheLongLineMovedOutwards) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    auto recs = plan(cfg, {line_to({10}, 50, tol, 0), line_to({10, 0.25}, 50, tol, 1),
                           line_to({10, 10.25}, 50, tol, 2)});
    ASSERT_EQ(recs.size(), 5u);
    const double d = 0.99 * tol;
    const double limit = 0.995 * tol;
    const double lp = 0.995 * std::pow(std::sqrt(limit + d) + std::sqrt(limit), 2);
    EXPECT_NEAR(lp, 5.7618 * tol, 1e-4 * tol);
    EXPECT_NEAR((lp - d) * (lp - d) / (4 * lp), 0.98797 * tol, 1e-5 * tol);
    const double ls = 3 * std::sqrt(2 * lp * 1000) * std::sqrt(6 * d / (0.5 * 1000));
    // The long line, the shift along it, the turn (the next move's, as blends are), the rest of
    // the short line (it keeps all but lp - d: the turn ends d short of lp past the corner).
    EXPECT_EQ(recs[0].geom.kind, ElementKind::Line);
    EXPECT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    EXPECT_EQ(recs[2].geom.kind, ElementKind::Bezier);
    EXPECT_EQ(recs[3].geom.kind, ElementKind::Line);
    EXPECT_EQ(recs[1].line, 0);
    EXPECT_EQ(recs[2].line, 1);
    EXPECT_NEAR(recs[0].geom.length_mm, 10 - lp - ls, 1e-12);
    EXPECT_NEAR(recs[2].geom.length_mm, 2 * lp, 1e-12);
    EXPECT_NEAR(recs[3].geom.length_mm, 0.25 - (lp - d), 1e-12);
    EXPECT_NEAR(recs[4].geom.length_mm, 10, 1e-12);
    // The turn runs at sqrt(0.99 x 990 x 2 lp) = 10.627 mm/s, 1.2 x the 8.855 mm/s of the
    // parabola inside the corner.
    const double v = std::sqrt(0.99 * 990 * 2 * lp);
    EXPECT_NEAR(recs[2].profile.peak_v_mm_s, v, 1e-9);
    EXPECT_NEAR(v, 10.627, 0.001);
    EXPECT_GT(v, 1.2 * std::sqrt(0.99 * 990 * 2 * 4 * tol));
    // d outside the long line along the shift; never beyond 0.995 tol, never in the quadrant
    // x > 10, y < 0 (right_angle_deviation counts that as 1e9).
    EXPECT_NEAR(right_angle_deviation(recs[1]), d, 1e-6);
    EXPECT_NEAR(right_angle_deviation(recs[2]), d, 1e-6);
    MotionSample start = sample(recs[2], 0), end = sample(recs[2], recs[2].profile.duration_s);
    EXPECT_NEAR(start.pos_mm[0], 10 - lp, 1e-12);
    EXPECT_NEAR(start.pos_mm[1], -d, 1e-12);
    EXPECT_NEAR(end.pos_mm[0], 10, 1e-12);
    EXPECT_NEAR(end.pos_mm[1], lp - d, 1e-12);
}

// A rapid into a slow feed move: the blend runs at the feed (4 mm/s) whatever its cut, so it is
// cut only as long as passing at exactly the feed needs on the share an isolated blend turns
// with, l = 4^2 |dT_x| / (2 * 0.99 * 990) = 0.008163 mm (|dT_x| = 1 at 90 degrees) instead of
// the tolerance's 0.04 mm, and the rapid keeps the rest at its own speed. The blend is isolated
// (0.99): its cap sqrt(0.99 * 990 * 2l) is the feed itself. (Until 2026-11-22 the cut was for
// 1.05 x the feed on 0.95: 0.009378 mm, a turn 15 % longer than needed.)
TEST(Planner, RapidIntoSlowFeedIsBlendedOnlyAsFarAsTheFeedNeeds) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    PathSegment rapid = line_to({10}, 0, 0.01, 0);
    rapid.rapid = true;
    auto recs = plan(cfg, {rapid, line_to({10, 10}, 4, 0.01, 1)});
    ASSERT_EQ(recs.size(), 3u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    double l = 4.0 * 4.0 / (2 * 0.99 * 990);
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    EXPECT_NEAR(recs[0].geom.length_mm, 10 - l, 1e-12);
    EXPECT_NEAR(recs[1].profile.peak_v_mm_s, 4, 1e-9);
    EXPECT_LT(right_angle_deviation(recs[1]), 0.01);
}

// A peck-drill reversal (down to Z-6, straight back up) must reach Z-6: a blend there would
// stay on the line, within any path tolerance, and still drill the hole short.
TEST(Planner, ReversalIsAnExactStopAtItsEndPoint) {
    for (double jerk : {0.0, 1e5}) {
        PlannerConfig cfg = uniform(100, 1000, jerk);
        auto recs = plan(cfg, {line_to({0, 0, -6}, 50, 0.05, 0), line_to({0, 0, -1}, 50, 0.05, 1)});
        ASSERT_EQ(recs.size(), 2u) << "jerk " << jerk;
        EXPECT_EQ(recs[0].geom.kind, ElementKind::Line);
        EXPECT_NEAR(recs[0].geom.length_mm, 6, 1e-12) << "jerk " << jerk;
        MotionSample end = sample(recs[0], recs[0].profile.duration_s);
        EXPECT_NEAR(end.pos_mm[2], -6, 1e-12) << "jerk " << jerk;
        EXPECT_NEAR(end.vel_mm_s[2], 0, 1e-9) << "jerk " << jerk;
    }
}

// Past 90 degrees of turn the cut is l = tol / ((1/4) |T2 - T1| / sqrt(2)), so the parabola
// misses the corner point by |T2 - T1| l / 4 = sqrt(2) tol, as at a right angle. (135 degrees:
// past the 120 degrees up to which a one-sided offset corner is tried.)
TEST(Planner, SharpTurnBlendMissesTheCornerPointByNoMoreThanARightAngle) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    const double c = std::cos(3 * M_PI / 4), s = std::sin(3 * M_PI / 4);
    auto recs = plan(cfg, {line_to({10}, 50, tol, 0), line_to({10 + 10 * c, 10 * s}, 50, tol, 1)});
    ASSERT_EQ(recs.size(), 3u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    const double dt = std::sqrt(2 - 2 * c);  // |T2 - T1|
    const double l = 4 * tol * std::sqrt(2.0) / dt;
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    // The parabola's middle is (P0 + 2 P1 + P2) / 4 with P1 the corner.
    MotionSample mid = sample(recs[1], recs[1].profile.duration_s / 2);
    const double miss = std::hypot(mid.pos_mm[0] - 10, mid.pos_mm[1]);
    EXPECT_NEAR(miss, std::sqrt(2.0) * tol, 1e-6);
}

TEST(Planner, BlendedRightAngleIsTheQuarticWithJerkLimit) {
    PlannerConfig cfg = uniform(100, 1000, 1e9);  // a jerk limit too high to bind here
    const double tol = 0.01;
    auto recs = plan(cfg, {line_to({10}, 50, tol, 0), line_to({10, 10}, 50, tol, 1)});
    ASSERT_EQ(recs.size(), 3u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Blend);
    // Cut per side: l = tol / ((3/16) sin(90 deg)).
    double l = tol / (3.0 / 16.0);
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    // Speed through it: the axis curvature bound 1.5 |dT_k| / 2l with |dT_k| = 1 against the
    // blend's centripetal share (0.95) of the usable acceleration.
    double v = std::sqrt(0.95 * 1000 * (1 - override_reserve_in_effect(cfg)) * 2 * l / 1.5);
    EXPECT_NEAR(recs[1].profile.peak_v_mm_s, v, 1e-9);
    EXPECT_NEAR(right_angle_deviation(recs[1]), tol, 1e-6);
}

PathSegment arc_to(AxisArray end, std::array<double, 2> centre, int turns, double feed, double tol,
                   int line) {
    PathSegment s = line_to(end, feed, tol, line);
    s.kind = SegmentKind::Arc;
    s.centre_mm = centre;
    s.turns = turns;
    return s;
}

struct CornerReport {
    double worst_dev_mm = 0;     // largest distance from the programmed moves
    double worst_acc_ratio = 0;  // largest |a_k| / limit
    double worst_vel_ratio = 0;
    double worst_jerk_ratio = 0;  // with a jerk limit
    int stops = 0;                // records other than the last ending at rest
    int beziers = 0;
};

// Samples every record `samples` times against the programmed moves (segment line = index) and
// the limits; inside a blend (tagged with the next move) the previous move counts too.
CornerReport check_corners(const PlannerConfig& cfg, const test::Program& prog,
                           const std::vector<PreparedSegment>& recs, int samples = 200) {
    std::vector<Element> elems = test::programmed_elements(prog);
    CornerReport rep;
    for (std::size_t r = 0; r < recs.size(); ++r) {
        const PreparedSegment& rec = recs[r];
        rep.beziers += rec.geom.kind == ElementKind::Bezier;
        if (r + 1 < recs.size() && rec.profile.at(rec.profile.duration_s).v_mm_s < 1e-9)
            ++rep.stops;
        for (int i = 0; i <= samples; ++i) {
            MotionSample s = sample(rec, rec.profile.duration_s * i / samples);
            auto line = static_cast<std::size_t>(rec.line);
            double d = test::distance_to(elems[line], s.pos_mm);
            if (line > 0) d = std::min(d, test::distance_to(elems[line - 1], s.pos_mm));
            rep.worst_dev_mm = std::max(rep.worst_dev_mm, d);
            for (int k = 0; k < kAxes; ++k) {
                rep.worst_acc_ratio = std::max(rep.worst_acc_ratio,
                                               std::fabs(s.acc_mm_s2[k]) / cfg.limits.acc_mm_s2[k]);
                rep.worst_vel_ratio = std::max(rep.worst_vel_ratio,
                                               std::fabs(s.vel_mm_s[k]) / cfg.limits.vel_mm_s[k]);
                if (cfg.limits.jerk_mm_s3[k] > 0)
                    rep.worst_jerk_ratio =
                        std::max(rep.worst_jerk_ratio,
                                 std::fabs(s.jerk_mm_s3[k]) / cfg.limits.jerk_mm_s3[k]);
            }
        }
    }
    return rep;
}

// Corners with arcs: line -> arc (entering the circle at 90 degrees to its tangent), arc -> arc
// (two circles meeting at 45 degrees), arc -> line (leaving at 60 degrees), and a helix -> line
// corner; each blended within the tolerance instead of stopped, with or without a jerk limit.
// (A Bezier blend's ends are curvature steps: under a jerk limit it is used only where they
// can be passed at a good part of the feed, which 1e9 mm/s^3 allows here; lower limits stop.)
class ArcCorners : public ::testing::TestWithParam<double> {};

TEST_P(ArcCorners, AreBlendedWithinToleranceAndLimits) {
    const double tol = 0.02;
    PlannerConfig cfg = uniform(100, 1000, GetParam());
    test::Program prog;
    prog.start = {0, 0, 0};
    const double r = 5;
    // 0: line along +X to (5, 0). 1: clockwise half-way round (10, 0), starting along +Y
    // (a 90 degree line -> arc corner) and ending at (10, 5) along +X.
    prog.segs.push_back(line_to({5, 0}, 40, tol, 0));
    prog.segs.push_back(arc_to({10, 5}, {10, 0}, -1, 40, tol, 1));
    // 2: counter-clockwise about (10 + c, 5 + c), starting along (1, -1) / sqrt 2 (a 45 degree
    // arc -> arc corner) and ending along +Y.
    const double c = r / std::sqrt(2.0);
    prog.segs.push_back(arc_to({10 + c + r, 5 + c}, {10 + c, 5 + c}, 1, 40, tol, 2));
    // 3: a line at 120 degrees (a 30 degree arc -> line corner).
    const double dir = 2 * std::numbers::pi / 3;
    AxisArray p3 = prog.segs[2].end_mm;
    prog.segs.push_back(
        line_to({p3[0] + 10 * std::cos(dir), p3[1] + 10 * std::sin(dir)}, 40, tol, 3));
    // 4: a clockwise helix half-way round a centre 5 mm along +X, rising 3 mm in Z (a 30 degree
    // line -> helix corner); 5: a line along -Y (an 11 degree helix -> line corner).
    AxisArray p4 = prog.segs[3].end_mm;
    PathSegment helix = arc_to({p4[0] + 10, p4[1], 3}, {p4[0] + 5, p4[1]}, -1, 40, tol, 4);
    prog.segs.push_back(helix);
    AxisArray p5 = helix.end_mm;
    prog.segs.push_back(line_to({p5[0], p5[1] - 5, 3}, 40, tol, 5));
    auto recs = plan(cfg, prog.segs, prog.start);
    CornerReport rep = check_corners(cfg, prog, recs);
    EXPECT_EQ(rep.stops, 0);
    EXPECT_GE(rep.beziers, 5);
    EXPECT_LE(rep.worst_dev_mm, tol * (1 + 1e-9));
    EXPECT_LE(rep.worst_acc_ratio, 1 + 1e-9);
    EXPECT_LE(rep.worst_vel_ratio, 1 + 1e-9);
    EXPECT_LE(rep.worst_jerk_ratio, 1 + 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Jerk, ArcCorners, ::testing::Values(0.0, 1e9));

// Without a jerk limit a right angle from a line into an arc is cut on the moves carried
// outwards (offset_arc_corner), as between two lines: the tool shifts d outwards off the line
// (y < 0), turns between the line moved to y = -d and the arc carried d along its radius
// (radius R - d: the outward normal at the corner, +X, points to the arc's centre), and shifts
// back onto the arc. The arc's chords (corner_path: n = ceil(dphi sqrt(R / (8 0.02 tol))) over
// the longest cut) leave a slack R (dphi / n)^2 / 8 that both the offset and the turn keep clear
// of: share = 0.99 - slack / tol instead of 0.99, lp = 8 share tol, d = share tol.
TEST(Planner, LineIntoArcIsCutOnCarriedMovesWithoutJerkLimit) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01, r = 50;
    test::Program prog;
    prog.start = {-10, 0, 0};
    // 0: along +X to the origin; 1: clockwise a quarter round (50, 0), leaving along +Y.
    prog.segs.push_back(line_to({0, 0}, 50, tol, 0));
    prog.segs.push_back(arc_to({r, r}, {r, 0}, -1, 50, tol, 1));
    auto recs = plan(cfg, prog.segs, prog.start);
    ASSERT_EQ(recs.size(), 5u);
    for (int i = 1; i <= 3; ++i) ASSERT_EQ(recs[i].geom.kind, ElementKind::Bezier) << i;
    ASSERT_EQ(recs[4].geom.kind, ElementKind::Arc);
    EXPECT_EQ(recs[1].line, 0);
    EXPECT_EQ(recs[2].line, 1);
    EXPECT_EQ(recs[3].line, 1);
    // The shift length for a turn cut lp with offset d: 3 x the turn's speed sqrt(2 lp A) on
    // half the acceleration, the shift's second derivative peaking at 6 d / ls^2.
    auto shift_mm = [](double lp, double d) {
        return 3 * std::sqrt(2 * lp * 1000) * std::sqrt(6 * d / (0.5 * 1000));
    };
    const double lp0 = 8 * 0.99 * tol, d0 = 0.99 * tol;
    const double dphi = (lp0 - d0 + shift_mm(lp0, d0)) / r;  // the arc's longest cut
    const double chords = std::ceil(dphi * std::sqrt(r / (8 * 0.02 * tol)));
    EXPECT_EQ(chords, 2);
    const double slack = r * (dphi / chords) * (dphi / chords) / 8;
    const double share = 0.99 - slack / tol;
    const double lp = 8 * share * tol, d = share * tol, ls = shift_mm(lp, d);
    // Each move loses lp + ls less d tan(45 deg).
    EXPECT_NEAR(recs[0].geom.length_mm, 10 - (lp + ls - d), 1e-12);
    EXPECT_NEAR(recs[4].geom.length_mm, r * std::numbers::pi / 2 - (lp + ls - d), 1e-9);
    EXPECT_EQ(recs[4].geom.radius_mm, r);
    EXPECT_EQ(sample(recs[4], recs[4].profile.duration_s).pos_mm, prog.segs[1].end_mm);
    // The turn is nearly the two lines' parabola (the arc bends by lp / r = 0.0016 rad over
    // it): it passes at sqrt(0.99 x 990 x 2 lp) within 1 %, 1.40 x the 8.855 mm/s of the blend
    // inside the corner.
    const double v = std::sqrt(0.99 * 990 * 2 * lp);
    EXPECT_NEAR(recs[2].profile.peak_v_mm_s, v, 0.01 * v);
    EXPECT_GT(recs[2].profile.peak_v_mm_s, 1.39 * std::sqrt(0.99 * 990 * 8 * tol));
    // Within the tolerance (proved within 0.995 of it), reaching d outside the line on the
    // first shift, and within every axis's 990 mm/s^2.
    std::vector<Element> elems = test::programmed_elements(prog);
    double worst = 0, lowest_y = 0, worst_acc = 0;
    for (int i = 1; i <= 3; ++i) {
        for (int j = 0; j <= 1000; ++j) {
            MotionSample s = sample(recs[i], recs[i].profile.duration_s * j / 1000);
            worst = std::max(worst, std::min(test::distance_to(elems[0], s.pos_mm),
                                             test::distance_to(elems[1], s.pos_mm)));
            lowest_y = std::min(lowest_y, s.pos_mm[1]);
            for (int k = 0; k < 2; ++k) worst_acc = std::max(worst_acc, std::fabs(s.acc_mm_s2[k]));
        }
    }
    EXPECT_LE(worst, 0.995 * tol);
    EXPECT_NEAR(lowest_y, -d, 1e-6);
    EXPECT_LE(worst_acc, 990 * (1 + 1e-9));
}

// Where the moves allow little more than the blend inside the corner (an arc into a line at
// ex23's 10 mm/s feed, 1.13 x its 8.85 mm/s), the corner is the Bezier blend inside it: an
// offset corner would gain about 0.4 ms there and cost several proofs against the arc's chords.
TEST(Planner, ArcIntoLineAtALowFeedIsTheBlendInsideTheCorner) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    const double tol = 0.01;
    // A clockwise half circle from (-10, 0) round (-5, 0) ending along -Y, then a line along +X.
    auto recs = plan(cfg, {arc_to({0, 0}, {-5, 0}, -1, 10, tol, 0), line_to({10, 0}, 10, tol, 1)},
                     {-10, 0, 0});
    ASSERT_EQ(recs.size(), 3u);
    EXPECT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    // 0.995 tol inside a corner whose first side is an arc: a little less than the parabola's
    // 4 x 0.995 tol from each move (bezier_corner shrinks the first guess until proved).
    EXPECT_LE(recs[1].geom.length_mm, 2 * 4 * 0.995 * tol * (1 + 1e-12));
    EXPECT_GT(recs[1].geom.length_mm, 0.9 * 2 * 4 * 0.995 * tol);
    EXPECT_LT(recs[1].profile.peak_v_mm_s, 10);
}

// A run of small tangent arcs (alternating semicircles, end points rounded to 4 decimals as a
// CAM program writes them) flows at the feed: the time is the length at feed plus one ramp up
// and one down.
TEST(Planner, SmallTangentArcsFlowAtFeed) {
    PlannerConfig cfg = uniform(100, 1000, 0);
    test::Program prog;
    const double r = 1.2345, feed = 20;  // v^2 / r = 324 mm/s^2: within the centripetal share
    std::vector<PathSegment>& segs = prog.segs;
    double x = 0;
    for (int i = 0; i < 200; ++i) {
        double end = std::round((x + 2 * r) * 1e4) / 1e4;
        segs.push_back(arc_to({end, 0}, {x + r, 0}, i % 2 ? 1 : -1, feed, 0.01, i));
        x = end;
    }
    auto recs = plan(cfg, segs, prog.start);
    double length = 200 * std::numbers::pi * r;
    // Speeding up and slowing down at a tangential acceleration of at least half the usable
    // 900 mm/s^2 (the centripetal part takes some of it on arcs) loses feed / a at most.
    double ramp_s = feed / 450;
    EXPECT_LE(total_time(recs), length / feed + ramp_s);
    CornerReport rep = check_corners(cfg, prog, recs, 20);
    EXPECT_EQ(rep.stops, 0);
    EXPECT_LE(rep.worst_dev_mm, 0.01 * (1 + 1e-9));
    EXPECT_LE(rep.worst_acc_ratio, 1 + 1e-9);
}

TEST(Planner, ArcSpeedRespectsCentripetalAcceleration) {
    // Full circle of radius 5 at F200: v^2 / r within the arc's centripetal share (0.95 without
    // a jerk limit) of the usable acceleration (990, the 1 % reserve kept without a jerk limit
    // taken off): v = sqrt(0.95 * 990 * 5) = 68.575 mm/s.
    PlannerConfig cfg = uniform(100, 1000, 0);
    PathSegment arc;
    arc.kind = SegmentKind::Arc;
    arc.end_mm = {10, 0};
    arc.centre_mm = {5, 0};
    arc.feed_mm_s = 200;
    arc.turns = 1;
    auto recs = plan(cfg, {arc}, {10, 0});
    ASSERT_EQ(recs.size(), 1u);
    EXPECT_NEAR(recs[0].profile.peak_v_mm_s, std::sqrt(0.95 * 990 * 5), 1e-9);
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
