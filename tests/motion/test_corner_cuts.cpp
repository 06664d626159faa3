// How the planner cuts corners without a jerk limit, answers worked out by hand from the
// parabola's constant second derivative (t2 - t1) / 2l (docs/motion-planner.md, "Geometry"):
// a corner between a rapid (or a faster move) and a slow feed move, whose turn runs at the
// slower feed whatever its cut, so any cut longer than that speed needs only slows the turn;
// and a row end's corner onto a short sloped step, cut on offset lines with lane changes along
// one axis.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "motion/planner.hpp"
#include "program_gen.hpp"

namespace motion {
namespace {

constexpr double kTol = 0.01;
constexpr double kAcc = 1000, kUsable = 0.99 * kAcc;  // the planner keeps a 1 % reserve

PlannerConfig machine() {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(100);
    cfg.limits.acc_mm_s2.fill(kAcc);
    cfg.limits.jerk_mm_s3.fill(0);
    return cfg;
}

PathSegment move(AxisArray end, double feed_mm_s, int line, bool rapid = false) {
    PathSegment s;
    s.end_mm = end;
    s.feed_mm_s = rapid ? 0 : feed_mm_s;
    s.rapid = rapid;
    s.tolerance_mm = kTol;
    s.line = line;
    return s;
}

std::vector<PreparedSegment> plan(const PlannerConfig& cfg, const test::Program& prog) {
    Planner p(cfg, prog.start);
    std::vector<PreparedSegment> out;
    PreparedSegment r;
    for (const auto& s : prog.segs) {
        p.push(s);
        while (p.pop(r)) out.push_back(r);
    }
    p.finish();
    while (p.pop(r)) out.push_back(r);
    return out;
}

// Every record sampled finely: within the tolerance of the programmed path (the nearest
// programmed move), each axis within its velocity and acceleration limit, and the last sample
// exactly at the program's end.
void expect_within_path_and_limits(const PlannerConfig& cfg, const test::Program& prog,
                                   const std::vector<PreparedSegment>& recs) {
    const std::vector<Element> path = test::programmed_elements(prog);
    double worst_mm = 0, worst_v = 0, worst_a = 0;
    for (const PreparedSegment& rec : recs) {
        for (int i = 0; i <= 400; ++i) {
            const MotionSample s = sample(rec, rec.profile.duration_s * i / 400);
            double nearest = 1e9;
            for (const Element& e : path) nearest = std::min(nearest, test::distance_to(e, s.pos_mm));
            worst_mm = std::max(worst_mm, nearest);
            for (int k = 0; k < kAxes; ++k) {
                worst_v = std::max(worst_v, std::fabs(s.vel_mm_s[k]) / cfg.limits.vel_mm_s[k]);
                worst_a = std::max(worst_a, std::fabs(s.acc_mm_s2[k]) / cfg.limits.acc_mm_s2[k]);
            }
        }
    }
    EXPECT_LE(worst_mm, kTol * (1 + 1e-9));
    EXPECT_LE(worst_v, 1 + 1e-9);
    EXPECT_LE(worst_a, 1 + 1e-9);
    const PreparedSegment& last = recs.back();
    const MotionSample end = sample(last, last.profile.duration_s);
    for (int k = 0; k < kAxes; ++k) EXPECT_EQ(end.pos_mm[k], prog.segs.back().end_mm[k]) << k;
}

// A rapid along X into a G1 along Y at 10 mm/s (F600, tp_default's plunge feed). The parabola
// inside the corner (cut 4 tol = 0.04 mm) would turn at sqrt(0.99 x 990 x 0.08) = 8.85 mm/s,
// below the feed, so the corner is cut on offset lines (offset_corner). Its turn runs at the
// feed, 10 mm/s, and needs a cut of only lp = v^2 |dT_k| / (2 x 0.99 x 990) = 0.05102 mm
// (|dT_k| = 1 for both axes at 90 degrees, 0.99 being the share a turn gets): 2 lp / v =
// 10.20 ms at the feed. A cut for 1.05 x the feed on the 0.95 share (the rule until
// 2026-11-22: lp = 0.05862 mm) takes 11.72 ms, and every 0.1 ms the turn takes longer is
// 0.1 ms more for the whole corner, as the turn is passed at the feed and the rapid keeps its
// speed up to it either way.
TEST(CornerCuts, RapidIntoASlowFeedTurnsOnTheShortestCutItsFeedNeeds) {
    const PlannerConfig cfg = machine();
    test::Program prog;
    prog.segs = {move({20}, 0, 0, true), move({20, 10}, 10, 1)};
    const auto recs = plan(cfg, prog);
    const double v = 10, lp = v * v / (2 * 0.99 * kUsable);
    EXPECT_NEAR(lp, 0.05102, 1e-5);
    int turns = 0;
    for (const PreparedSegment& r : recs) {
        if (r.geom.kind != ElementKind::Bezier || r.line != 1) continue;
        // The turn: it starts along +X and ends along +Y (the shift back starts along +Y).
        const EndDerivs a = start_derivs(r.geom, false), b = end_derivs(r.geom, false);
        if (!(a.tangent[0] > 0.99 && b.tangent[1] > 0.99)) continue;
        ++turns;
        EXPECT_NEAR(r.profile.peak_v_mm_s, v, 1e-9);
        EXPECT_NEAR(r.geom.length_mm, 2 * lp, 1e-12);
        EXPECT_LE(r.profile.duration_s, 2 * lp / v * (1 + 1e-9));
        EXPECT_LT(r.profile.duration_s, 0.0103);
    }
    EXPECT_EQ(turns, 1);
    expect_within_path_and_limits(cfg, prog, recs);
}

// The same corner onto a 0.03 mm feed move: the parabola is not isolated (the short move keeps
// less than twice its cut), so close_piece gives it the default 0.95 share for turning, and a
// cut for the feed on 0.99 would cap it at 4 x sqrt(0.95 / 0.99) = 3.92 mm/s, below the feed.
// It is cut for its own share instead: l = 4^2 / (2 x 0.95 x 990) = 0.008506 mm, passed at the
// feed.
TEST(CornerCuts, ANonIsolatedParabolaAfterARapidIsCutForItsOwnShare) {
    const PlannerConfig cfg = machine();
    test::Program prog;
    prog.segs = {move({10}, 0, 0, true), move({10, 0.03}, 4, 1), move({20, 0.03}, 4, 2)};
    const auto recs = plan(cfg, prog);
    ASSERT_GE(recs.size(), 2u);
    ASSERT_EQ(recs[1].geom.kind, ElementKind::Bezier);
    const double l = 4.0 * 4.0 / (2 * 0.95 * kUsable);
    EXPECT_NEAR(recs[1].geom.length_mm, 2 * l, 1e-12);
    EXPECT_NEAR(recs[0].geom.length_mm, 10 - l, 1e-12);
    EXPECT_NEAR(recs[1].profile.peak_v_mm_s, 4, 1e-9);
    expect_within_path_and_limits(cfg, prog, recs);
}

// tp_default's X0 row end, second corner: the 5 mm Y step (+Y) onto a 0.5 mm step along
// (0.5, 0.1) (79 degrees), then the row goes on along the same direction. The short step used to
// leave no room for the lane change back (half of it, 0.255 mm, below the 2/3 x 0.41 mm the
// offset corner needs), so the corner was cut one-sided at 10.84 mm/s. A line of at most 1 mm
// now gives 0.9 of itself, so the offset corner fits: the turn is the parabola between the two
// lines moved d = 0.99 tol outwards, cut lp = 2 x 0.99 tol / (sin(angle) / 4) = 0.08073 mm
// (sin(angle) = 0.98058), passed at sqrt(0.99 x 990 x 2 lp / |dT_x|) = 12.71 mm/s (|dT_x| =
// 0.98058 is the larger of |dT_x|, |dT_y| = 0.80388). The lane change back onto the sloped step
// moves the tool along Y only (its outward normal lies 0.98 along Y), so X runs on as along the
// line: its second derivative is only what the Bezier's parametrisation gives (a few % of Y's),
// where a shift along the normal (-0.196, 0.981) would give X 0.2 of Y's.
TEST(CornerCuts, RowEndOntoAShortSlopedStepIsCutOnOffsetLinesShiftingAlongOneAxis) {
    const PlannerConfig cfg = machine();
    test::Program prog;
    prog.segs = {move({0, 10}, 50, 0), move({0.5, 10.1}, 50, 1), move({10.5, 12.1}, 50, 2)};
    const auto recs = plan(cfg, prog);
    const double s = 1 / std::sqrt(1.04), sin_angle = std::sqrt(1 - s * s * 0.04);
    EXPECT_NEAR(sin_angle, 0.98058, 1e-5);
    const double lp = 2 * 0.99 * kTol / (sin_angle / 4);
    const double v = std::sqrt(0.99 * kUsable * 2 * lp / s);  // |dT_x| = s = 0.98058
    EXPECT_NEAR(v, 12.71, 0.01);
    std::vector<const PreparedSegment*> beziers;
    for (const PreparedSegment& r : recs)
        if (r.geom.kind == ElementKind::Bezier) beziers.push_back(&r);
    // Shift out (on the Y step's line), the turn and the shift back (the next move's).
    ASSERT_EQ(beziers.size(), 3u);
    EXPECT_EQ(beziers[0]->line, 0);
    EXPECT_EQ(beziers[1]->line, 1);
    EXPECT_EQ(beziers[2]->line, 1);
    EXPECT_NEAR(beziers[1]->geom.length_mm, 2 * lp, 1e-12);
    EXPECT_NEAR(beziers[1]->profile.peak_v_mm_s, v, 1e-6);
    const ElementBounds back = bounds(beziers[2]->geom);
    EXPECT_GT(back.g2[1], 0);
    EXPECT_LT(back.g2[0], 0.05 * back.g2[1]);
    expect_within_path_and_limits(cfg, prog, recs);
}

}  // namespace
}  // namespace motion
