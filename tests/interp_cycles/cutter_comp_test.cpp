// Cutter radius compensation: hand-computed offset paths for small contours,
// the manual's two programs (S0 §3.5.3), and every error.
//
// Expected geometry is derived by hand: a line offset to the left by r moves
// by r along (−dy, dx)/|d|; an inside corner of two axis-parallel lines is the
// crossing of the two shifted lines; an outside corner is a quarter arc of
// radius r about the programmed corner.

#include "interp/cutter_comp.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using namespace interp::cutter;
using Lines = std::vector<std::string>;

double clean(double v) {
    const double r = std::round(v * 1e6) / 1e6;
    return r == 0 ? 0 : r;
}

const char* role_name(Role r) {
    switch (r) {
        case Role::Plain:
            return "plain";
        case Role::Startup:
            return "startup";
        case Role::Contour:
            return "contour";
        case Role::Corner:
            return "corner";
        case Role::Cancel:
            return "cancel";
        case Role::Height:
            return "height";
    }
    return "?";
}

std::string describe(const Output& o) {
    if (const auto* m = std::get_if<OutMove>(&o)) {
        std::string s = fmt::format("{} {:g},{:g} -> {:g},{:g}",
                                    m->shape == Shape::Line ? "L" : "A", clean(m->start.x()),
                                    clean(m->start.y()), clean(m->end.x()), clean(m->end.y()));
        if (m->shape == Shape::Arc)
            s += fmt::format(" c{:g},{:g} {} {:g}deg", clean(m->centre.x()), clean(m->centre.y()),
                             m->ccw ? "ccw" : "cw", clean(m->sweep_rad * 180 / M_PI));
        if (m->start_h != m->end_h || m->start_h != 0)
            s += fmt::format(" h{:g}->{:g}", clean(m->start_h), clean(m->end_h));
        return s + fmt::format(" {} #{}", role_name(m->role), m->tag);
    }
    if (const auto* k = std::get_if<OutMarker>(&o)) return fmt::format("marker #{}", k->tag);
    return "warning #" + std::to_string(std::get<OutWarning>(o).tag);
}

Move line(double x, double y, Side side, double r, SourceTag tag, bool rapid = false) {
    Move m;
    m.end = {x, y};
    m.side = side;
    m.radius_mm = r;
    m.tag = tag;
    m.rapid = rapid;
    return m;
}

Move arc(double x, double y, double cx, double cy, bool ccw, Side side, double r, SourceTag tag) {
    Move m = line(x, y, side, r, tag);
    m.shape = Shape::Arc;
    m.centre = {cx, cy};
    m.ccw = ccw;
    return m;
}

Move at_h(Move m, double h) {
    m.end_h = h;
    return m;
}

Move height(double h, Side side, double r, SourceTag tag, Vec2 at) {
    Move m = line(at.x(), at.y(), side, r, tag);
    m.end_h = h;
    return m;
}

Lines run(Compensator& c, const std::vector<Move>& moves, bool finish = true) {
    for (const auto& m : moves) c.push(m);
    if (finish) c.finish();
    Lines out;
    for (const auto& o : c.drain()) out.push_back(describe(o));
    return out;
}

// Starts at (5, 5) so that a first move to (0, 0) moves in the plane.
CompError error_of(const std::vector<Move>& moves, Config cfg = {}, Vec2 start = {5, 5}) {
    Compensator c(cfg, start);
    try {
        run(c, moves);
    } catch (const CompError& e) {
        return e;
    }
    return CompError("no error", 0, 0);
}

constexpr Side L = Side::Left;
constexpr Side R = Side::Right;
constexpr Side Off = Side::Off;

TEST(CutterComp, ManualProgram2RunsWithPerpendicularStartAndCancel) {
    // G92 X0 Y0 / G0 G41 X10 Y10 D01 / G1 X20 Y10 / G0 G40 X0 Y0, with r = 2:
    // start-up ends on the perpendicular of block 3 at its start (10, 12); the
    // contour runs at y = 12; the cancel leaves from (20, 12) to (0, 0).
    Compensator c;
    EXPECT_EQ(
        run(c, {line(10, 10, L, 2, 2, true), line(20, 10, L, 2, 3), line(0, 0, Off, 2, 4, true)}),
        (Lines{"L 0,0 -> 10,12 startup #2", "L 10,12 -> 20,12 contour #3",
               "L 20,12 -> 0,0 cancel #4"}));
}

TEST(CutterComp, ManualProgram1IsAPathReversal) {
    const CompError e =
        error_of({line(10, 10, L, 2, 2, true), line(20, 10, L, 2, 3), line(0, 10, Off, 2, 4, true)},
                 Config{}, {0, 0});
    EXPECT_STREQ(e.what(), "cutter comp: path reversal (with the move at line 3)");
    EXPECT_EQ(e.earlier_block, 3);
    EXPECT_EQ(e.at_block, 4);
}

TEST(CutterComp, ReversalInsideTheContourToo) {
    // S1: "G1 X5 Y10" after "G1 X20 Y10" is an error.
    const CompError e =
        error_of({line(10, 10, L, 2, 2), line(20, 10, L, 2, 3), line(5, 10, L, 2, 4)});
    EXPECT_STREQ(e.what(), "cutter comp: path reversal (with the move at line 3)");
}

TEST(CutterComp, OutsideCornersGetArcsAroundTheCornerPoint) {
    // A CCW 10×10 square with G42 (tool right of travel = outside), r = 1.
    Compensator c(Config{}, {-5, -5});
    EXPECT_EQ(run(c, {line(0, 0, R, 1, 1), line(10, 0, R, 1, 2), line(10, 10, R, 1, 3),
                      line(0, 10, R, 1, 4), line(0, 0, R, 1, 5), line(-5, -5, Off, 1, 6)}),
              (Lines{"L -5,-5 -> 0,-1 startup #1", "L 0,-1 -> 10,-1 contour #2",
                     "A 10,-1 -> 11,0 c10,0 ccw 90deg corner #3", "L 11,0 -> 11,10 contour #3",
                     "A 11,10 -> 10,11 c10,10 ccw 90deg corner #4", "L 10,11 -> 0,11 contour #4",
                     "A 0,11 -> -1,10 c0,10 ccw 90deg corner #5", "L -1,10 -> -1,0 contour #5",
                     "L -1,0 -> -5,-5 cancel #6"}));
}

TEST(CutterComp, ExtendedLineCornersWhenConfigured) {
    Config cfg;
    cfg.extend_max_turn_deg = 90;
    Compensator c(cfg, {-5, -5});
    const Lines out = run(c, {line(0, 0, R, 1, 1), line(10, 0, R, 1, 2), line(10, 10, R, 1, 3),
                              line(-5, 10, Off, 1, 4)});
    EXPECT_EQ(out, (Lines{"L -5,-5 -> 0,-1 startup #1", "L 0,-1 -> 10,-1 contour #2",
                          "L 10,-1 -> 11,-1 corner #3", "L 11,-1 -> 11,0 corner #3",
                          "L 11,0 -> 11,10 contour #3", "L 11,10 -> -5,10 cancel #4"}));
}

TEST(CutterComp, InsideCornersAreTrimmedToTheIntersection) {
    // The same square with G41 (tool inside), from the centre and back with the
    // ISO cancel: the cancel turns toward the tool (inside), so the last move
    // stops where its offset x = 1 meets the cancel line shifted left by 1,
    // y = x + √2, instead of running on to (1, 0) next to the bottom edge.
    Config cfg;
    cfg.cancel_at_inside_corner = CancelCorner::Intersection;
    Compensator c(cfg, {5, 5});
    EXPECT_EQ(run(c, {line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), line(10, 10, L, 1, 3),
                      line(0, 10, L, 1, 4), line(0, 0, L, 1, 5), line(5, 5, Off, 1, 6)}),
              (Lines{"L 5,5 -> 0,1 startup #1", "L 0,1 -> 9,1 contour #2",
                     "L 9,1 -> 9,9 contour #3", "L 9,9 -> 1,9 contour #4",
                     "L 1,9 -> 1,2.41421 contour #5", "L 1,2.41421 -> 5,5 cancel #6"}));
    // An outside cancel is unchanged: the manual's program 2.
    Compensator p2(cfg);
    EXPECT_EQ(
        run(p2, {line(10, 10, L, 2, 2, true), line(20, 10, L, 2, 3), line(0, 0, Off, 2, 4, true)})
            .back(),
        "L 20,12 -> 0,0 cancel #4");
}

TEST(CutterComp, FullCircleInsideShrinksTheRadius) {
    // G41 G1 X10 / G3 X10 Y0 I-10 (full CCW circle, tool inside) / G40 G1 X0, r 2.
    Compensator c;
    EXPECT_EQ(
        run(c, {line(10, 0, L, 2, 1), arc(10, 0, 0, 0, true, L, 2, 2), line(0, 0, Off, 2, 3)}),
        (Lines{"L 0,0 -> 8,0 startup #1", "A 8,0 -> 8,0 c0,0 ccw 360deg contour #2",
               "L 8,0 -> 0,0 cancel #3"}));
}

TEST(CutterComp, LineToArcInsideCornerMeetsTheShrunkCircle) {
    // Left comp r 1: line (0,0)→(10,0), then a CCW arc of radius 10 about (10,10)
    // starting straight down... i.e. from (10,0) heading +X: tangent, no corner.
    // Make a corner instead: line (0,-10)→(10,0) (heading 45°), then the same arc
    // (heading +X at its start) turns right by 45°: outside for G41 → corner arc.
    Compensator c(Config{}, {-10, -10});
    const Lines out = run(c, {line(0, -10, L, 1, 1), line(10, 0, L, 1, 2),
                              arc(20, 10, 10, 10, true, L, 1, 3), line(20, 20, Off, 1, 4)});
    ASSERT_EQ(out.size(), 5u);
    EXPECT_EQ(out[2], fmt::format("A {:g},{:g} -> 10,1 c10,0 cw 45deg corner #3",
                                  clean(10 - std::sqrt(0.5)), clean(std::sqrt(0.5))));
    EXPECT_EQ(out[3], "A 10,1 -> 19,10 c10,10 ccw 90deg contour #3");
}

TEST(CutterComp, HelixOffsetInPlaneHeightFollows) {
    Compensator c;
    Move h = arc(10, 0, 0, 0, true, L, 2, 2);
    h.end_h = -3;
    const Lines out = run(c, {line(10, 0, L, 2, 1), h, line(0, 0, Off, 2, 3)});
    EXPECT_EQ(out[1], "A 8,0 -> 8,0 c0,0 ccw 360deg h0->-3 contour #2");
}

TEST(CutterComp, ManualExample2Obround) {
    // S0 §3.12 example 2 (EX-19) with D01 = 5: the contour runs clockwise, so G41
    // (left) is outside: the CW arcs grow to radius 30 and the lines move out by 5.
    // Start-up ends on the perpendicular of the first arc at (45,15): its tangent
    // there is −X, left of that is −Y, so (45,10). All joints are tangent.
    Compensator c;
    EXPECT_EQ(
        run(c, {line(45, 15, L, 5, 2, true), arc(45, 65, 45, 40, false, L, 5, 3),
                line(135, 65, L, 5, 4), arc(135, 15, 135, 40, false, L, 5, 5),
                line(45, 15, L, 5, 6), line(0, 0, Off, 5, 7, true)}),
        (Lines{"L 0,0 -> 45,10 startup #2", "A 45,10 -> 45,70 c45,40 cw 180deg contour #3",
               "L 45,70 -> 135,70 contour #4", "A 135,70 -> 135,10 c135,40 cw 180deg contour #5",
               "L 135,10 -> 45,10 contour #6", "L 45,10 -> 0,0 cancel #7"}));
}

TEST(CutterComp, ManualExample3NotchCornersAreInsideCorners) {
    // S0 §3.12 example 3 (EX-20), absolute points, D = 5, G41 (outside of this
    // clockwise contour). The notch (100,120)→(100,70)→(140,70)→(140,120) turns
    // left twice: inside corners at (105,75) and (135,75); its top corners turn
    // right: outside, arcs about (100,120) and (140,120).
    Compensator c;
    const Lines out = run(
        c, {line(40, 30, L, 5, 2, true), line(40, 100, L, 5, 3),
            arc(60, 120, 60, 100, false, L, 5, 4), line(100, 120, L, 5, 5), line(100, 70, L, 5, 6),
            line(140, 70, L, 5, 7), line(140, 120, L, 5, 8), line(210, 120, L, 5, 9),
            line(210, 80, L, 5, 10), arc(160, 30, 210, 30, true, L, 5, 11), line(40, 30, L, 5, 12),
            line(0, 0, Off, 5, 13, true)});
    const Lines expected_parts{"L 0,0 -> 35,30 startup #2",
                               "L 35,30 -> 35,100 contour #3",
                               "A 35,100 -> 60,125 c60,100 cw 90deg contour #4",
                               "L 60,125 -> 100,125 contour #5",
                               "A 100,125 -> 105,120 c100,120 cw 90deg corner #6",
                               "L 105,120 -> 105,75 contour #6",
                               "L 105,75 -> 135,75 contour #7",
                               "L 135,75 -> 135,120 contour #8",
                               "A 135,120 -> 140,125 c140,120 cw 90deg corner #9",
                               "L 140,125 -> 210,125 contour #9",
                               "A 210,125 -> 215,120 c210,120 cw 90deg corner #10",
                               "L 215,120 -> 215,80 contour #10",
                               "L 40,25 -> 0,0 cancel #13"};
    for (const auto& part : expected_parts)
        EXPECT_NE(std::find(out.begin(), out.end(), part), out.end()) << part;
    // The CCW arc about (210,30) with the tool on its left (centre side) shrinks to
    // 45; it starts heading −X after line 10 heads −Y: a right turn, outside.
    for (const char* part :
         {"A 215,80 -> 210,75 c210,80 cw 90deg corner #11",
          "A 210,75 -> 165,30 c210,30 ccw 90deg contour #11",
          "A 165,30 -> 160,25 c160,30 cw 90deg corner #12", "L 160,25 -> 40,25 contour #12"})
        EXPECT_NE(std::find(out.begin(), out.end(), part), out.end()) << part;
}

TEST(CutterComp, ZMovesAndMarkersWaitAtTheCorner) {
    // A Z plunge and an M code between the first two contour moves come out
    // after the corner, at the offset start of the next move.
    Compensator c(Config{}, {-5, -5});
    c.push(line(0, 0, R, 1, 1));
    c.push(line(10, 0, R, 1, 2));
    c.push(height(-2, R, 1, 3, {10, 0}));
    c.push(Marker{4});
    c.push(at_h(line(10, 10, R, 1, 5), -2));
    c.push(at_h(line(20, 10, Off, 1, 6), -2));
    c.finish();
    Lines out;
    for (const auto& o : c.drain()) out.push_back(describe(o));
    EXPECT_EQ(out,
              (Lines{"L -5,-5 -> 0,-1 startup #1", "L 0,-1 -> 10,-1 contour #2",
                     "A 10,-1 -> 11,0 c10,0 ccw 90deg corner #5", "L 11,0 -> 11,0 h0->-2 height #3",
                     "marker #4", "L 11,0 -> 11,10 h-2->-2 contour #5",
                     "L 11,10 -> 20,10 h-2->-2 cancel #6"}));
}

TEST(CutterComp, TooManyMovesWithoutPlaneMotion) {
    Config cfg;
    cfg.lookahead_moves = 2;
    std::vector<Move> moves{line(0, 0, L, 1, 1), line(10, 0, L, 1, 2)};
    for (int i = 0; i < 3; ++i) moves.push_back(height(-i - 1.0, L, 1, 3 + i, {10, 0}));
    moves.push_back(at_h(line(10, 10, L, 1, 6), -3));
    const CompError e = error_of(moves, cfg);
    EXPECT_STREQ(e.what(),
                 "cutter comp: more than 2 blocks without motion in the compensation plane (with "
                 "the move at line 2)");
    EXPECT_EQ(e.at_block, 5);
    // With the perpendicular fallback the path ends on the perpendicular and restarts.
    cfg.on_exhausted = OnLookaheadExhausted::Perpendicular;
    // The restart goes to the perpendicular of line 6 at its start, (9, 0).
    Compensator c(cfg, {0, -5});
    const Lines out = run(c, moves);
    EXPECT_EQ(out[1], "L 0,1 -> 10,1 contour #2");
    EXPECT_EQ(out[5], "L 10,1 -> 9,0 h-3->-3 startup #6");
    EXPECT_EQ(out[6], "L 9,0 -> 9,10 h-3->-3 contour #6");
}

TEST(CutterComp, SideSwitchLinksToTheNewSide) {
    Compensator c(Config{}, {-5, 0});
    const Lines out = run(c, {line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), line(20, 0, R, 1, 3),
                              line(30, 0, Off, 1, 4)});
    EXPECT_EQ(out, (Lines{"L -5,0 -> 0,1 startup #1", "L 0,1 -> 10,1 contour #2",
                          "L 10,1 -> 10,-1 startup #3", "L 10,-1 -> 20,-1 contour #3",
                          "L 20,-1 -> 30,0 cancel #4"}));
}

TEST(CutterComp, CancelInABlockWithoutPlaneMotionReturnsToTheProgrammedPoint) {
    Compensator c;
    const Lines out =
        run(c, {line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), height(5, Off, 1, 3, {10, 0})});
    EXPECT_EQ(out.back(), "L 10,1 -> 10,0 h0->5 cancel #3");
    EXPECT_FALSE(c.active());
}

TEST(CutterComp, NegativeRadiusSwapsTheSide) {
    // G41 with a radius of −1 offsets to the right, like G42 with 1.
    Compensator c(Config{}, {-5, 0});
    const Lines out =
        run(c, {line(0, 0, L, -1, 1), line(10, 0, L, -1, 2), line(15, 0, Off, -1, 3)});
    EXPECT_EQ(out, (Lines{"L -5,0 -> 0,-1 startup #1", "L 0,-1 -> 10,-1 contour #2",
                          "L 10,-1 -> 15,0 cancel #3"}));
}

TEST(CutterComp, ProgramEndWithCompensationActiveWarns) {
    Compensator c(Config{}, {-5, 0});
    const Lines out = run(c, {line(0, 0, L, 1, 1), line(10, 0, L, 1, 2)});
    EXPECT_EQ(out, (Lines{"L -5,0 -> 0,1 startup #1", "L 0,1 -> 10,1 contour #2", "warning #2"}));
}

TEST(CutterComp, CompensationOffPassesMovesThrough) {
    Compensator c;
    const Lines out = run(c, {line(5, 0, Off, 0, 1), arc(5, 10, 5, 5, true, Off, 0, 2)});
    EXPECT_EQ(out, (Lines{"L 0,0 -> 5,0 plain #1", "A 5,0 -> 5,10 c5,5 ccw 180deg plain #2"}));
}

// ---- moves too short for the tool ------------------------------------------------

TEST(CutterCompShortMoves, ChamferSmallerThanTheToolIsSkipped) {
    // G41 (tool inside) along +X with a 0.5 chamfer (19.5,0)→(20,0.5) into +Y, r = 2. The
    // chamfer's offset (its line moved 2 toward the pocket) meets y = 2 at x = 20.33, 0.33 beyond
    // the chamfer's own offset: the tool cannot touch it. The +X and +Y offsets, y = 2 and x = 18,
    // meet at (18, 2), which is |18 − 2 − 19.5|/√2 = 2.47 ≥ 2 from the chamfer: skipping it keeps
    // exactly 2 from both walls and more than 2 from the chamfer.
    Compensator c(Config{}, {5, 5});
    EXPECT_EQ(run(c, {line(0, 0, L, 2, 1), line(19.5, 0, L, 2, 2), line(20, 0.5, L, 2, 3),
                      line(20, 20, L, 2, 4), line(20, 25, Off, 2, 5)}),
              (Lines{"L 5,5 -> 0,2 startup #1", "L 0,2 -> 18,2 contour #2",
                     "L 18,2 -> 18,20 contour #4", "L 18,20 -> 20,25 cancel #5"}));
}

TEST(CutterCompShortMoves, StepSmallerThanTheToolGoesRoundItsCorner) {
    // G41 (tool above) along +X, a 0.1 step up at x = 10, then +X again; r = 1. The step's
    // offset x = 9 meets y = 1 at y-parameter 10 (beyond the step): skipped. The step's top
    // corner (10, 0.1) turns right (outside), so the tool leaves y = 1 where it comes within 1 of
    // that corner, x = 10 − √(1 − 0.9²) = 9.56411, and goes round it (clockwise, from 115.842° to
    // 90°) to (10, 1.1) on the next move's offset.
    Compensator c(Config{}, {0, -5});
    EXPECT_EQ(run(c, {line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), line(10, 0.1, L, 1, 3),
                      line(20, 0.1, L, 1, 4), line(25, 0.1, Off, 1, 5)}),
              (Lines{"L 0,-5 -> 0,1 startup #1", "L 0,1 -> 9.56411,1 contour #2",
                     "A 9.56411,1 -> 10,1.1 c10,0.1 cw 25.8419deg corner #4",
                     "L 10,1.1 -> 20,1.1 contour #4", "L 20,1.1 -> 25,0.1 cancel #5"}));
}

TEST(CutterCompShortMoves, ChamferUsedUpByBothItsCornersIsSkipped) {
    // A 30° left turn at (10, 0) cut by an isosceles chamfer (9.9,0)→(10.0866,0.05) of length
    // 0.193 (15°), G41 r = 1. Each of its corners trims r·tan(7.5°) = 0.132 off its offset: the
    // first leaves 0.062 (< r, so line 2's piece waits), the second would need 0.132 more. The
    // chamfer is skipped; lines 2 and 4 meet where the tool touches both: on the bisector of the
    // original corner, x = 10 − r·tan(15°) = 9.73205, y = 1, which is 1.0094 from the chamfer.
    const double c30 = std::cos(M_PI / 6), s30 = 0.5;
    const Vec2 b_end(10 + 0.1 * c30, 0.1 * s30);
    Compensator c(Config{}, {0, -5});
    const Lines out =
        run(c, {line(0, 0, L, 1, 1), line(9.9, 0, L, 1, 2), line(b_end.x(), b_end.y(), L, 1, 3),
                line(b_end.x() + 10 * c30, b_end.y() + 10 * s30, L, 1, 4),
                line(b_end.x() + 20 * c30, b_end.y() + 20 * s30, Off, 1, 5)});
    ASSERT_EQ(out.size(), 4u);
    EXPECT_EQ(out[1], "L 0,1 -> 9.73205,1 contour #2");
    EXPECT_EQ(out[2].substr(0, 15), "L 9.73205,1 -> ");
    EXPECT_NE(out[2].find("contour #4"), std::string::npos) << out[2];
    for (const auto& o : out) EXPECT_EQ(o.find("#3"), std::string::npos) << o;
}

TEST(CutterCompShortMoves, SlotNarrowerThanTheToolIsAGouge) {
    // +X, 0.2 up, −X back: a slot 0.2 wide for a tool of radius 1 on its inside. The first and
    // last offsets, y = 1 and y = −0.8, never meet: no path keeps 1 from all three moves.
    const CompError e = error_of({line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), line(10, 0.2, L, 1, 3),
                                  line(0, 0.2, L, 1, 4), line(0, 5, Off, 1, 5)},
                                 Config{}, {0, -5});
    EXPECT_STREQ(e.what(),
                 "cutter comp: gouge: the tool radius 1 does not fit the inside corner (with the "
                 "move at line 2)");
    EXPECT_EQ(e.at_block, 4);
}

TEST(CutterCompShortMoves, NoSkippingWithoutTheGougeCheck) {
    // The chamfer of the first test: skipping is only safe when the gouge check proves it.
    Config cfg;
    cfg.gouge_check_moves = 0;
    const CompError e =
        error_of({line(0, 0, L, 2, 1), line(19.5, 0, L, 2, 2), line(20, 0.5, L, 2, 3),
                  line(20, 20, L, 2, 4), line(20, 25, Off, 2, 5)},
                 cfg);
    EXPECT_STREQ(e.what(),
                 "cutter comp: gouge: the tool radius 2 does not fit the inside corner (with the "
                 "move at line 2)");
    EXPECT_EQ(e.at_block, 3);
}

TEST(CutterCompShortMoves, ProgramEndingAfterASkippedMoveIsAGouge) {
    // The program ends after the chamfer: nothing places its corner, so the tool cannot leave.
    const CompError e =
        error_of({line(0, 0, L, 2, 1), line(19.5, 0, L, 2, 2), line(20, 0.5, L, 2, 3)});
    EXPECT_EQ(e.earlier_block, 2);
    EXPECT_EQ(e.at_block, 3);
}

// ---- errors -----------------------------------------------------------------

TEST(CutterCompErrors, StartOnAnArc) {
    const CompError e = error_of({line(10, 0, Off, 0, 1), arc(0, 10, 0, 0, true, L, 1, 2)});
    EXPECT_STREQ(
        e.what(),
        "cutter comp: compensation cannot start on an arc; start it with G00/G01 (with the "
        "move at line 1)");
    EXPECT_EQ(e.earlier_block, 1);
    EXPECT_EQ(e.at_block, 2);
}

TEST(CutterCompErrors, CancelOnAnArc) {
    const CompError e =
        error_of({line(10, 0, L, 1, 1), line(20, 0, L, 1, 2), arc(30, 0, 25, 0, true, Off, 1, 3)});
    EXPECT_STREQ(e.what(),
                 "cutter comp: compensation cannot be cancelled on an arc; cancel it with G00/G01 "
                 "(with the move at line 2)");
    EXPECT_EQ(e.at_block, 3);
}

TEST(CutterCompErrors, ToolLargerThanInsideArc) {
    // CCW arc of radius 3 with G41: the tool (r 4) is on the centre side.
    const CompError e = error_of({line(3, 0, L, 4, 1), arc(0, 3, 0, 0, true, L, 4, 2)});
    EXPECT_STREQ(e.what(),
                 "cutter comp: the tool radius 4 does not fit the inside arc of radius 3 (with the "
                 "move at line 1)");
    EXPECT_EQ(e.earlier_block, 1);
    EXPECT_EQ(e.at_block, 2);
}

TEST(CutterCompErrors, GougeWhenTheToolDoesNotFitAnInsideCorner) {
    // Inside a 10×10 square with r 6: the offsets of the bottom and right edges meet at (4, 6),
    // leaving 4 < r of the right edge's offset, so line 2's piece waits. The top edge's offset
    // y = 4 meets x = 4 below y = 6: the right edge is used up, so line 2 must meet line 4
    // directly, and y = 6 and y = 4 never meet.
    const CompError e = error_of({line(0, 0, L, 6, 1), line(10, 0, L, 6, 2), line(10, 10, L, 6, 3),
                                  line(0, 10, L, 6, 4), line(0, 0, L, 6, 5)});
    EXPECT_STREQ(e.what(),
                 "cutter comp: gouge: the tool radius 6 does not fit the inside corner (with the "
                 "move at line 2)");
    EXPECT_EQ(e.at_block, 4);
}

TEST(CutterCompErrors, GougeIntoAnEarlierMove) {
    // The perpendicular cancel (default) of the inside square ends the last
    // move at (1, 0), on the bottom edge (line 2): the look-back check refuses it.
    const CompError e =
        error_of({line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), line(10, 10, L, 1, 3),
                  line(0, 10, L, 1, 4), line(0, 0, L, 1, 5), line(5, 5, Off, 1, 6)});
    EXPECT_STREQ(e.what(),
                 "cutter comp: gouge: the tool (radius 1) would come within 0 of the contour of "
                 "line 2 (with the move at line 5)");
    EXPECT_EQ(e.contour_block, 2);
    EXPECT_EQ(e.earlier_block, 5);
    EXPECT_EQ(e.at_block, 6);  // the cancel fixes where line 5 ends
    // Non-adjacent moves: line 6 runs back 2 above line 2 with r = 1.5 on the
    // side facing it. Every corner is fine locally (the corners between are
    // 10–20 long), but the corner before line 6 and line 6 itself pass 0.5 from line 2.
    const CompError far =
        error_of({line(0, 0, L, 1.5, 1), line(20, 0, L, 1.5, 2), line(20, 20, L, 1.5, 3),
                  line(10, 20, L, 1.5, 4), line(10, 2, L, 1.5, 5), line(0, 2, L, 1.5, 6),
                  line(-5, 2, Off, 1.5, 7)},
                 Config{}, {0, -5});
    EXPECT_STREQ(far.what(),
                 "cutter comp: gouge: the tool (radius 1.5) would come within 0.5 of the contour "
                 "of line 2 (with the move at line 5)");
    EXPECT_EQ(far.at_block, 6);  // the corner into line 6 passes 0.5 from line 2
    Config off;
    off.gouge_check_moves = 0;
    EXPECT_STREQ(error_of({line(0, 0, L, 1.5, 1), line(20, 0, L, 1.5, 2), line(20, 20, L, 1.5, 3),
                           line(10, 20, L, 1.5, 4), line(10, 2, L, 1.5, 5), line(0, 2, L, 1.5, 6),
                           line(-5, 2, Off, 1.5, 7)},
                          off, {0, -5})
                     .what(),
                 "no error");
}

TEST(CutterCompErrors, PlaneChangeWhileActive) {
    Move m = line(10, 10, L, 1, 3);
    m.plane = 18;
    const CompError e = error_of({line(0, 0, L, 1, 1), line(10, 0, L, 1, 2), m});
    EXPECT_STREQ(e.what(),
                 "cutter comp: the plane changed from G17 to G18 while compensation is active "
                 "(with the move at line 2)");
}

TEST(CutterCompErrors, PositionCannotBeSetWhileActive) {
    Compensator c;
    c.push(line(10, 0, L, 1, 1));
    EXPECT_THROW(c.set_position({0, 0}, 0), CompError);
}

}  // namespace
