// Canned cycles: each cycle's step list against the numbered "加工过程说明"
// steps of S0 §3.6.4 applied to the manual's own example (tool at X0 Y0 Z10,
// G90, F800, R-5, Z-10, hole at X5 Y5). The expected lists were written by hand
// from those steps before running the code; zero-length moves (e.g. step 1 when
// the tool is already above the hole, or a G99 "retract to R" when already at R)
// are not emitted.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "cycle_test_util.hpp"

namespace {

using namespace cycle_test;
using Lines = std::vector<std::string>;

struct Session {
    CycleState state;
    BlockContext ctx = manual_context();
    CycleConfig cfg;

    Lines run(std::optional<CycleCode> code, const CycleWords& w) {
        const Expansion e = state.run_block(code, w, ctx, cfg);
        ctx.position_mm = end_position(e, ctx.position_mm);
        return texts(e);
    }
};

TEST(CannedCycle, G81ManualExampleAllFiveHoles) {
    Session s;
    s.ctx.return_to_r = true;  // G99
    // Hole 1: G00 to X5 Y5, G00 to R, G01 to Z, G00 to R (G99).
    EXPECT_EQ(
        s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5)),
        (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "rapid X5 Y5 Z-5"}));
    // Hole 2 "X25": Z R retained; already at R so step 2 is empty.
    EXPECT_EQ(s.run(std::nullopt, Words().x(25)),
              (Lines{"rapid X25 Y5 Z-5", "feed X25 Y5 Z-10 F800", "rapid X25 Y5 Z-5"}));
    EXPECT_EQ(s.run(std::nullopt, Words().y(25)),
              (Lines{"rapid X25 Y25 Z-5", "feed X25 Y25 Z-10 F800", "rapid X25 Y25 Z-5"}));
    // Hole 4 "G98 X5": returns to the initial level latched at the first block (Z10).
    s.ctx.return_to_r = false;
    EXPECT_EQ(s.run(std::nullopt, Words().x(5)),
              (Lines{"rapid X5 Y25 Z-5", "feed X5 Y25 Z-10 F800", "rapid X5 Y25 Z10"}));
    // Hole 5 "X10 Y10 Z-20": new Z, from the initial level again.
    EXPECT_EQ(s.run(std::nullopt, Words().x(10).y(10).z(-20)),
              (Lines{"rapid X10 Y10 Z10", "rapid X10 Y10 Z-5", "feed X10 Y10 Z-20 F800",
                     "rapid X10 Y10 Z10"}));
}

TEST(CannedCycle, G82DwellsPInMillisecondsAtTheBottom) {
    Session s;
    s.ctx.return_to_r = true;
    EXPECT_EQ(s.run(CycleCode::G82, Words().x(5).y(5).z(-10).r(-5).p(2000)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "dwell 2s",
                     "rapid X5 Y5 Z-5"}));
}

TEST(CannedCycle, G73PecksQAndBacksOffDelta) {
    // R-5 to Z-10 with Q2: feed to -7, up δ=0.5 to -6.5, feed to -9, up to -8.5,
    // feed the remaining 1 mm to -10, then rapid to R (G99).
    Session s;
    s.ctx.return_to_r = true;
    s.cfg.retract_mm = 0.5;
    EXPECT_EQ(s.run(CycleCode::G73, Words().x(5).y(5).z(-10).r(-5).q(2)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-7 F800",
                     "rapid X5 Y5 Z-6.5", "feed X5 Y5 Z-9 F800", "rapid X5 Y5 Z-8.5",
                     "feed X5 Y5 Z-10 F800", "rapid X5 Y5 Z-5"}));
}

TEST(CannedCycle, G83ReturnsToRAfterEveryPeck) {
    // Q3: feed to -8, rapid to R -5, rapid down to δ=0.5 above -8 (-7.5), feed
    // to -10 (Q would reach -11), rapid to R.
    Session s;
    s.ctx.return_to_r = true;
    s.cfg.retract_mm = 0.5;
    EXPECT_EQ(s.run(CycleCode::G83, Words().x(5).y(5).z(-10).r(-5).q(3)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-8 F800", "rapid X5 Y5 Z-5",
                     "rapid X5 Y5 Z-7.5", "feed X5 Y5 Z-10 F800", "rapid X5 Y5 Z-5"}));
}

TEST(CannedCycle, G74TapsLeftHandWithReversalsAndDwells) {
    // 3) G01 to Z 4) dwell P, reverse 5) G01 to R 6) dwell P, reverse 7) G00 to
    // the initial level (G98 here). Tapping feeds lock the feed override (G74-2).
    Session s;
    s.ctx.spindle = Spindle::Ccw;
    EXPECT_EQ(s.run(CycleCode::G74, Words().x(5).y(5).z(-10).r(-5).p(2000)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800 locked",
                     "dwell 2s", "spindle reverse", "feed X5 Y5 Z-5 F800 locked", "dwell 2s",
                     "spindle reverse", "rapid X5 Y5 Z10"}));
}

TEST(CannedCycle, G84UsesTheTappingSpeedParameterAndRestoresS) {
    Session s;
    s.ctx.return_to_r = true;
    s.cfg.tap_spindle_rpm = 300;
    EXPECT_EQ(
        s.run(CycleCode::G84, Words().x(5).y(5).z(-10).r(-5).p(2000)),
        (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "spindle speed S300",
               "feed X5 Y5 Z-10 F800 locked", "dwell 2s", "spindle reverse",
               "feed X5 Y5 Z-5 F800 locked", "dwell 2s", "spindle reverse", "spindle speed S600"}));
}

TEST(CannedCycle, TappingNeedsTheMatchingSpindleDirection) {
    Session s;  // spindle CW
    try {
        s.run(CycleCode::G74, Words().x(5).y(5).z(-10).r(-5));
        FAIL() << "G74 with M03 must fail";
    } catch (const CycleError& e) {
        EXPECT_STREQ(e.what(),
                     "G74 needs the spindle running counter-clockwise (M04) before the cycle");
    }
    s.ctx.spindle = Spindle::Stopped;
    EXPECT_THROW(s.run(CycleCode::G84, Words().x(5).y(5).z(-10).r(-5)), CycleError);
}

TEST(CannedCycle, G76OrientsShiftsInTheOssDirectionAndShiftsBack) {
    // 3) G01 to Z, dwell 5 s, oriented stop 4) shift Q2 along OSS 0 = +X (G17)
    // 5) G00 to R (G99) 6) restart; REC G76-1 shifts back before the restart.
    Session s;
    s.ctx.return_to_r = true;
    EXPECT_EQ(s.run(CycleCode::G76, Words().x(5).y(5).z(-10).r(-5).q(2).p(5000)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "dwell 5s",
                     "spindle orient tip=(-1 0 0)", "rapid X7 Y5 Z-10", "rapid X7 Y5 Z-5",
                     "rapid X5 Y5 Z-5",
                     "spindle restart"}));
}

TEST(CannedCycle, OssTablesGiveTheManualsDirections) {
    struct Case {
        OssTable table;
        int oss;
        const char* shifted;
    };
    // NcStudio: 0 +X, 1 −X, 2 +Y, 3 −Y. ISO: 1 +X, 0/2 −X, 3 +Y, 4 −Y.
    const Case cases[] = {
        {OssTable::NcStudio, 1, "rapid X3 Y5 Z-10"}, {OssTable::NcStudio, 2, "rapid X5 Y7 Z-10"},
        {OssTable::NcStudio, 3, "rapid X5 Y3 Z-10"}, {OssTable::Iso, 0, "rapid X3 Y5 Z-10"},
        {OssTable::Iso, 1, "rapid X7 Y5 Z-10"},      {OssTable::Iso, 4, "rapid X5 Y3 Z-10"},
    };
    for (const auto& c : cases) {
        Session s;
        s.cfg.oss_table = c.table;
        s.cfg.oss_direction = c.oss;
        const Lines lines = s.run(CycleCode::G76, Words().x(5).y(5).z(-10).r(-5).q(2));
        ASSERT_GE(lines.size(), 5u);
        EXPECT_EQ(lines[4], c.shifted) << "oss " << c.oss;
    }
    Session bad;
    bad.cfg.oss_direction = 4;  // not in the NcStudio table
    EXPECT_THROW(bad.run(CycleCode::G76, Words().x(5).y(5).z(-10).r(-5).q(2)), CycleError);
}

TEST(CannedCycle, G85FeedsOutToR) {
    Session s;  // G98
    EXPECT_EQ(s.run(CycleCode::G85, Words().x(5).y(5).z(-10).r(-5)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800",
                     "feed X5 Y5 Z-5 F800", "rapid X5 Y5 Z10"}));
}

TEST(CannedCycle, G86StopsTheSpindleAndRestartsAtTheReturnLevel) {
    Session s;
    EXPECT_EQ(s.run(CycleCode::G86, Words().x(5).y(5).z(-10).r(-5)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "spindle stop",
                     "rapid X5 Y5 Z10", "spindle restart"}));
}

TEST(CannedCycle, G87BackBoresUpFromRWithShiftsAroundTheTool) {
    // R-15 is the hole bottom, Z-5 the top of the bore, Q5 along OSS 0 (+X):
    // 1) G00 to X5 Y5 2) orient, shift −Q 3) G00 down to R, shift +Q 4) spindle CW
    // 5) G01 up to Z 6) dwell 4 s, orient, shift −Q 7) G00 to the initial level
    // 8) shift +Q, restart.
    Session s;
    EXPECT_EQ(s.run(CycleCode::G87, Words().x(5).y(5).z(-5).r(-15).q(5).p(4000)),
              (Lines{"rapid X5 Y5 Z10", "spindle orient tip=(1 0 0)", "rapid X0 Y5 Z10",
                     "rapid X0 Y5 Z-15", "rapid X5 Y5 Z-15", "spindle cw", "feed X5 Y5 Z-5 F800",
                     "dwell 4s", "spindle orient tip=(1 0 0)", "rapid X0 Y5 Z-5", "rapid X0 Y5 Z10", "rapid X5 Y5 Z10",
                     "spindle restart"}));
}

TEST(CannedCycle, G87TreatsG99AsG98WithAWarning) {
    Session s;
    s.ctx.return_to_r = true;
    const Expansion e =
        s.state.run_block(CycleCode::G87, Words().x(5).y(5).z(-5).r(-15).q(5), s.ctx, s.cfg);
    ASSERT_EQ(e.warnings.size(), 1u);
    EXPECT_EQ(to_string(e.steps[e.steps.size() - 3]), "rapid X0 Y5 Z10");
}

TEST(CannedCycle, G87WithRAboveZRunsAsWrittenWithAWarning) {
    // FEATURES A-10: the manual's own G87 example (Z-10 R-5) puts R above Z. It is a flow test:
    // the steps run as programmed (the "feed up to Z" goes down from R -5 to Z -10) and warn.
    Session s;
    s.ctx.return_to_r = false;
    const Expansion e =
        s.state.run_block(CycleCode::G87, Words().x(5).y(5).z(-10).r(-5).q(5), s.ctx, s.cfg);
    ASSERT_EQ(e.warnings.size(), 1u);
    EXPECT_EQ(e.warnings[0],
              "G87 back boring: the R plane (-5) lies above Z (-10); R is meant to be the hole "
              "bottom, the steps run as programmed");
    EXPECT_EQ(texts(e),
              (Lines{"rapid X5 Y5 Z10", "spindle orient tip=(1 0 0)", "rapid X0 Y5 Z10",
                     "rapid X0 Y5 Z-5", "rapid X5 Y5 Z-5", "spindle cw", "feed X5 Y5 Z-10 F800",
                     "spindle orient tip=(1 0 0)", "rapid X0 Y5 Z-10", "rapid X0 Y5 Z10",
                     "rapid X5 Y5 Z10", "spindle restart"}));
}

TEST(CannedCycle, G88FeedRetractAndManualRetract) {
    // 3) G01 to Z 4) dwell P, spindle stop 5) G01 to R 6) G00 to initial 7) restart.
    Session s;
    EXPECT_EQ(s.run(CycleCode::G88, Words().x(5).y(5).z(-10).r(-5).p(2000)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "dwell 2s",
                     "spindle stop", "feed X5 Y5 Z-5 F800", "rapid X5 Y5 Z10", "spindle restart"}));
    Session m;
    m.cfg.g88_retract = G88Retract::Manual;
    EXPECT_EQ(m.run(CycleCode::G88, Words().x(5).y(5).z(-10).r(-5)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "spindle stop",
                     "operator retract", "rapid X5 Y5 Z10", "spindle restart"}));
}

TEST(CannedCycle, G89DwellsThenFeedsOut) {
    Session s;
    s.ctx.return_to_r = true;
    EXPECT_EQ(s.run(CycleCode::G89, Words().x(5).y(5).z(-10).r(-5).p(2500)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "dwell 2.5s",
                     "feed X5 Y5 Z-5 F800"}));
}

// ---- data rules -------------------------------------------------------------

TEST(CycleData, IncrementalRepeatDrillsEquallySpacedHoles) {
    // S0 §3.8 N03/N04: tool at X-50 Y51.963 Z20, "G91 G81 X20 Z-18 R-17 K4".
    // G91: R = initial + (−17) = 3, Z = R + (−18) = −15; four holes 20 apart
    // at X −30, −10, 10, 30, each returning to the initial level 20 (G98).
    Session s;
    s.ctx.position_mm = {-50, 51.963, 20};
    s.ctx.incremental = true;
    s.ctx.feed_mm_min = 4000;
    const Lines lines = s.run(CycleCode::G81, Words().x(20).z(-18).r(-17).k(4));
    Lines expected;
    for (double x : {-30.0, -10.0, 10.0, 30.0}) {
        const std::string xy = fmt::format("X{:g} Y51.963", x);
        expected.push_back("rapid " + xy + " Z20");
        expected.push_back("rapid " + xy + " Z3");
        expected.push_back("feed " + xy + " Z-15 F4000");
        expected.push_back("rapid " + xy + " Z20");
    }
    EXPECT_EQ(lines, expected);
    // N05 "X10 Y-17.321": one hole, same levels.
    const Lines next = s.run(std::nullopt, Words().x(10).y(-17.321));
    ASSERT_EQ(next.size(), 4u);
    EXPECT_EQ(next[2], "feed X40 Y34.642 Z-15 F4000");
}

TEST(CycleData, ManualExample4LeftHandTappingL2) {
    // S0 §3.12 example 4 (EX-21): after G92 X0 Y0 Z0 and "G91 G00 X-35 Y15 M04",
    // "G74 X50 Y0 Z-28 R-5 P1000 F1000 L2" under G91: R = 0 − 5, Z = R − 28 = −33,
    // two holes 50 apart at X15 and X65, each returning to the initial level 0
    // (G98). The following G00 blocks cancel the cycle (CC-13), so only 2 taps.
    Session s;
    s.ctx.position_mm = {-35, 15, 0};
    s.ctx.incremental = true;
    s.ctx.spindle = Spindle::Ccw;
    s.ctx.feed_mm_min = 1000;
    Lines expected;
    for (const char* x : {"X15", "X65"}) {
        const std::string xy = std::string(x) + " Y15";
        for (const std::string& line :
             {"rapid " + xy + " Z0", "rapid " + xy + " Z-5", "feed " + xy + " Z-33 F1000 locked",
              std::string("dwell 1s"), std::string("spindle reverse"),
              "feed " + xy + " Z-5 F1000 locked", std::string("dwell 1s"),
              std::string("spindle reverse"), "rapid " + xy + " Z0"})
            expected.push_back(line);
    }
    EXPECT_EQ(s.run(CycleCode::G74, Words().x(50).y(0).z(-28).r(-5).p(1000).k(2)), expected);
}

TEST(CycleData, AbsoluteRepeatDrillsTheSameHoleAgain) {
    Session s;
    s.ctx.return_to_r = true;
    const Lines lines = s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5).k(3));
    EXPECT_EQ(std::count(lines.begin(), lines.end(), "feed X5 Y5 Z-10 F800"), 3);
}

TEST(CycleData, K0StoresTheDataWithoutDrilling) {
    Session s;
    EXPECT_TRUE(s.run(CycleCode::G81, Words().z(-20).r(-5).k(0)).empty());
    EXPECT_TRUE(s.state.active());
    EXPECT_EQ(s.run(std::nullopt, Words().x(100)),
              (Lines{"rapid X100 Y0 Z10", "rapid X100 Y0 Z-5", "feed X100 Y0 Z-20 F800",
                     "rapid X100 Y0 Z10"}));
}

TEST(CycleData, ABlockWithoutPositionOrRDrillsNothing) {
    Session s;
    s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5));
    EXPECT_TRUE(s.run(std::nullopt, Words().p(100)).empty());  // e.g. only F/M/P words
    EXPECT_FALSE(s.run(std::nullopt, Words().r(-4)).empty());  // an R word alone drills
}

TEST(CycleData, InitialLevelIsLatchedOnlyWhenCycleModeStarts) {
    Session s;
    s.ctx.return_to_r = true;
    s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5));  // initial 10, tool now at R
    s.ctx.return_to_r = false;
    // Switching G81 → G82 without G80 keeps the initial level 10, not the R level.
    const Lines lines = s.run(CycleCode::G82, Words().x(15));
    EXPECT_EQ(lines.back(), "rapid X15 Y5 Z10");
    EXPECT_DOUBLE_EQ(s.state.data().initial_level_mm, 10.0);
}

TEST(CycleData, G80ClearsTheCycleAndItsData) {
    Session s;
    s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5).q(2).p(100));
    s.state.cancel();
    EXPECT_FALSE(s.state.active());
    EXPECT_FALSE(s.state.data().z_level_mm);
    EXPECT_FALSE(s.state.data().q_mm);
    try {
        s.run(std::nullopt, Words().x(1));
        FAIL();
    } catch (const CycleError& e) {
        EXPECT_STREQ(e.what(), "no canned cycle is active");
    }
    // A new cycle needs Z again.
    EXPECT_THROW(s.run(CycleCode::G81, Words().x(1)), CycleError);
}

TEST(CycleData, QSignIsIgnored) {
    Session a, b;
    a.cfg.retract_mm = b.cfg.retract_mm = 0.5;
    EXPECT_EQ(a.run(CycleCode::G73, Words().x(5).y(5).z(-10).r(-5).q(-2)),
              b.run(CycleCode::G73, Words().x(5).y(5).z(-10).r(-5).q(2)));
    EXPECT_DOUBLE_EQ(*a.state.data().q_mm, 2.0);
}

TEST(CycleData, LevelsAreStoredAbsoluteAcrossAG90G91Switch) {
    Session s;
    s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5));
    s.ctx.incremental = true;
    const Lines lines = s.run(std::nullopt, Words().x(10));  // G91 X10: a hole at X15
    EXPECT_EQ(lines[2], "feed X15 Y5 Z-10 F800");
}

TEST(CycleData, IncrementalZWithoutRStartsFromTheInitialLevel) {
    Session s;
    s.ctx.incremental = true;
    const Lines lines = s.run(CycleCode::G81, Words().x(0).z(-12));
    EXPECT_EQ(lines, (Lines{"feed X0 Y0 Z-2 F800", "rapid X0 Y0 Z10"}));
}

TEST(CycleData, G98NeverReturnsBelowR) {
    // The cycle starts with the tool at Z-2, below R0: G98 returns to R, not to -2.
    Session s;
    s.ctx.position_mm = {0, 0, -2};
    EXPECT_EQ(
        s.run(CycleCode::G81, Words().x(5).z(-10).r(0)),
        (Lines{"rapid X5 Y0 Z-2", "rapid X5 Y0 Z0", "feed X5 Y0 Z-10 F800", "rapid X5 Y0 Z0"}));
}

TEST(CycleData, IsoDrillAxisFollowsThePlane) {
    // G18 (ZX plane): the hole position is in Z and X, the drilling axis is Y.
    Session s;
    s.cfg.drill_axis_follows_plane = true;
    s.ctx.plane = Plane::ZX;
    s.ctx.position_mm = {0, 10, 0};
    EXPECT_EQ(
        s.run(CycleCode::G81, Words().x(3).z(4).y(-10).r(-5)),
        (Lines{"rapid X3 Y10 Z4", "rapid X3 Y-5 Z4", "feed X3 Y-10 Z4 F800", "rapid X3 Y10 Z4"}));
}

// ---- errors -----------------------------------------------------------------

std::string error_of(Session& s, std::optional<CycleCode> code, const CycleWords& w) {
    try {
        s.run(code, w);
    } catch (const CycleError& e) {
        return e.what();
    }
    return "no error";
}

TEST(CycleErrors, EachMessage) {
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G81, Words().x(5).r(-5)),
                  "G81: the hole bottom Z is missing (program Z in the first block of the cycle)");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G83, Words().x(5).z(-10).r(-5)),
                  "G83: the peck depth Q is missing");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G73, Words().x(5).z(-10).r(-5).q(0)),
                  "G73: the peck depth Q must not be 0");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G81, Words().x(5).z(-10).r(-5).k(-1)),
                  "the repeat count K must be a whole number in 0…99999999, got -1");
    }
    {
        Session s;
        s.ctx.drill_axis_scaled = true;
        EXPECT_EQ(error_of(s, CycleCode::G81, Words().x(5).z(-10).r(-5)),
                  "a canned cycle cannot run while the drilling axis is scaled (G51)");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G81, Words().x(5).z(-1).r(-5)),
                  "G81: the hole bottom Z (-1) lies above the R plane (-5)");
    }
    {
        Session s;
        s.ctx.position_mm = {0, 0, -8};
        EXPECT_EQ(error_of(s, CycleCode::G87, Words().x(5).z(-5).r(-15)),
                  "G87 back boring: the initial level (-8) must lie above Z (-5), the tool returns "
                  "there past the bore");
    }
    {
        Session s;
        s.ctx.feed_mm_min = 0;
        EXPECT_EQ(error_of(s, CycleCode::G81, Words().x(5).z(-10).r(-5)),
                  "G81: no feed rate F programmed");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G82, Words().x(5).z(-10).r(-5).p(-1)),
                  "dwell P must not be negative, got -1");
    }
    {
        Session s;
        EXPECT_EQ(error_of(s, CycleCode::G73, Words().x(5).z(-1000).r(0).q(0.001)),
                  "G73: Q0.001 gives more than 100000 pecks for the depth 1000");
    }
    {
        Session s;
        s.cfg.retract_mm = -1;
        EXPECT_EQ(error_of(s, CycleCode::G73, Words().x(5).z(-10).r(0).q(1)),
                  "#FIXEDCYCLE_BACK must not be negative, it is -1");
    }
}

TEST(CycleErrors, ARejectedBlockChangesNothing) {
    Session s;
    s.run(CycleCode::G81, Words().x(5).y(5).z(-10).r(-5));
    const CycleData before = s.state.data();
    EXPECT_THROW(s.run(CycleCode::G83, Words().x(6).z(-20)), CycleError);  // no Q
    EXPECT_EQ(*s.state.data().code, CycleCode::G81);
    EXPECT_EQ(*s.state.data().z_level_mm, *before.z_level_mm);
}

// ---- custom cycles ----------------------------------------------------------

TEST(CustomCycle, FcVariablesFollowTheManualTable) {
    // S0 §4.1.1: #FC1/#FC2 hole X/Y, #FC3 Z level, #FC4 R level, #FC5 Q,
    // #FC7 F, #FC11 K, #FC12 G99→1, #FC13 G91→1, #FC14 initial height.
    CycleState st;
    BlockContext ctx = manual_context();
    ctx.return_to_r = true;
    const auto fc = st.run_custom_block(CycleCode::G86, Words().x(5).y(6).z(-10).r(-5).q(-2).k(2),
                                        ctx, CycleConfig{});
    ASSERT_TRUE(fc);
    EXPECT_EQ((*fc)[1], 5);
    EXPECT_EQ((*fc)[2], 6);
    EXPECT_EQ((*fc)[3], -10);
    EXPECT_EQ((*fc)[4], -5);
    EXPECT_EQ((*fc)[5], 2);
    EXPECT_EQ((*fc)[7], 800);
    EXPECT_EQ((*fc)[11], 2);
    EXPECT_EQ((*fc)[12], 1);
    EXPECT_EQ((*fc)[13], 0);
    EXPECT_EQ((*fc)[14], 10);
    EXPECT_EQ((*fc)[50], 0);
}

TEST(CustomCycle, UnderG91PositionsAreIncrementsAndLevelsAbsolute) {
    // FC-2: the example's "G91 G65 P786 L=#FC11" steps by #FC1/#FC2.
    CycleState st;
    BlockContext ctx = manual_context();
    ctx.incremental = true;
    const auto fc =
        st.run_custom_block(CycleCode::G86, Words().x(20).z(-18).r(-7).q(3), ctx, CycleConfig{});
    ASSERT_TRUE(fc);
    EXPECT_EQ((*fc)[1], 20);
    EXPECT_EQ((*fc)[2], 0);
    EXPECT_EQ((*fc)[4], 3);    // 10 − 7
    EXPECT_EQ((*fc)[3], -15);  // 3 − 18
    EXPECT_EQ((*fc)[13], 1);
    EXPECT_FALSE(st.run_custom_block(std::nullopt, Words().p(5), ctx, CycleConfig{}));
}

TEST(CycleCodes, MapGNumbers) {
    EXPECT_EQ(cycle_code_from_g(73), CycleCode::G73);
    EXPECT_EQ(cycle_code_from_g(89), CycleCode::G89);
    EXPECT_FALSE(cycle_code_from_g(80));
    EXPECT_FALSE(cycle_code_from_g(75));
    EXPECT_EQ(g_number(CycleCode::G84), 84);
}

}  // namespace
