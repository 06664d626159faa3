// The modal data of public.dat canned cycles (CustomCycles, FEATURES CC-19, FC-1, FC-2), the
// lazy hole generator (HoleRun) and the V5.4 G76 U/V shift (G76-4). Expected values were worked
// out by hand from the rules quoted in each test.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "cycle_test_util.hpp"

namespace {

using namespace cycle_test;
using Lines = std::vector<std::string>;
using Info = CustomCycles::BlockInfo;

Info block(std::optional<int> g, const CycleWords& w, bool incremental = false,
           bool return_to_r = false, Vec3 pos = {0, 0, 20}) {
    Info b;
    b.custom_g = g;
    b.words = w;
    b.ctx.incremental = incremental;
    b.ctx.return_to_r = return_to_r;
    b.ctx.position_mm = pos;
    return b;
}

TEST(CustomCycle, FirstBlockFillsTheFcVariablesOfTheManual) {
    // S0 §4.1.1 example 2: G90 G99 G86 X10 Y10 Z-10 R2 Q3 F300 from Z20.
    CustomCycles c;
    Info b = block(86, Words().x(10).y(10).z(-10).r(2).q(-3), false, true);
    b.f = 300;
    const auto run = c.block(b);
    ASSERT_TRUE(run);
    EXPECT_EQ(run->g, 86);
    const FcVariables& fc = run->fc;
    EXPECT_EQ(fc[1], 10);
    EXPECT_EQ(fc[2], 10);
    EXPECT_EQ(fc[3], -10);
    EXPECT_EQ(fc[4], 2);
    EXPECT_EQ(fc[5], 3);  // CC-7: Q's sign is ignored
    EXPECT_EQ(fc[6], 0);
    EXPECT_EQ(fc[7], 300);
    EXPECT_EQ(fc[11], 1);
    EXPECT_EQ(fc[12], 1);  // G99
    EXPECT_EQ(fc[13], 0);  // G90
    EXPECT_EQ(fc[14], 20);
    EXPECT_TRUE(c.active());
}

TEST(CustomCycle, BarePositionRerunsWithRetainedDataAndLatchedInitialLevel) {
    CustomCycles c;
    Info first = block(86, Words().x(10).y(10).z(-10).r(2).q(3).p(500), false, true);
    first.f = 300;
    ASSERT_TRUE(c.block(first));
    // "X30" from the R plane (the tool is at Z2 after a G99 hole): Z R Q P F kept (CC-11, CC-9),
    // #FC14 still the level where the cycle started (CC-3), not the current Z2.
    const auto run = c.block(block(std::nullopt, Words().x(30), false, true, {10, 10, 2}));
    ASSERT_TRUE(run);
    EXPECT_EQ(run->g, 86);
    EXPECT_EQ(run->fc[1], 30);
    EXPECT_EQ(run->fc[2], 10);  // Y not written: the current Y
    EXPECT_EQ(run->fc[3], -10);
    EXPECT_EQ(run->fc[4], 2);
    EXPECT_EQ(run->fc[5], 3);
    EXPECT_EQ(run->fc[6], 500);
    EXPECT_EQ(run->fc[7], 300);
    EXPECT_EQ(run->fc[14], 20);
    // A block without a position word runs nothing (CC-12), K0 neither (CC-10).
    Info feed_only = block(std::nullopt, Words(), false, true, {30, 10, 2});
    feed_only.f = 100;
    EXPECT_FALSE(c.block(feed_only));
    EXPECT_FALSE(c.block(block(std::nullopt, Words().x(50).k(0), false, true, {30, 10, 2})));
    const auto later = c.block(block(std::nullopt, Words().y(40), false, true, {30, 10, 2}));
    ASSERT_TRUE(later);
    EXPECT_EQ(later->fc[7], 100);  // the F of the intervening block is modal
}

TEST(CustomCycle, G91LevelsAreAbsoluteAndXYAreIncrements) {
    // FC-2: under G91, R is from the initial level (20 − 18 = 2), Z from R (2 − 12 = −10);
    // #FC1/#FC2 are the programmed increments, the subprogram moves with G91 L=#FC11.
    CustomCycles c;
    const auto run = c.block(block(86, Words().x(10).y(5).z(-12).r(-18).q(3).k(2), true));
    ASSERT_TRUE(run);
    EXPECT_EQ(run->fc[1], 10);
    EXPECT_EQ(run->fc[2], 5);
    EXPECT_EQ(run->fc[3], -10);
    EXPECT_EQ(run->fc[4], 2);
    EXPECT_EQ(run->fc[11], 2);
    EXPECT_EQ(run->fc[13], 1);
    EXPECT_EQ(run->fc[14], 20);
}

TEST(CustomCycle, G80AndGroup01CodesEndTheCycle) {
    CustomCycles c;
    ASSERT_TRUE(c.block(block(86, Words().x(10).y(10).z(-10).r(2))));
    Info g00 = block(std::nullopt, Words().x(40));
    g00.cancels = true;  // G00 X40: an ordinary rapid, no custom run
    EXPECT_FALSE(c.block(g00));
    EXPECT_FALSE(c.active());
    // A new cycle must give Z again: the cancel forgot it.
    EXPECT_THROW(c.block(block(86, Words().x(10))), CycleError);
}

TEST(CustomCycle, MissingZIsTheBuiltInError) {
    CustomCycles c;
    try {
        c.block(block(81, Words().x(1).r(2)));
        FAIL();
    } catch (const CycleError& e) {
        EXPECT_STREQ(e.what(),
                     "G81: the hole bottom Z is missing (program Z in the first block of the "
                     "cycle)");
    }
    EXPECT_FALSE(c.active());
}

TEST(HoleRun, HolesAreMadeOneAtATime) {
    // G91 K99999999 (the largest count): the run knows its count but has made nothing yet;
    // each next() yields exactly one hole, 2 mm further along X.
    CycleState st;
    BlockContext ctx = manual_context();
    ctx.incremental = true;
    BlockHoles b = st.start_block(CycleCode::G81, Words().x(2).z(-5).r(-5).k(kMaxRepeat), ctx,
                                  CycleConfig{});
    EXPECT_EQ(b.holes.hole_count(), kMaxRepeat);
    EXPECT_EQ(b.holes.holes_done(), 0);
    std::vector<Step> steps;
    for (int hole = 1; hole <= 3; ++hole) {
        ASSERT_TRUE(b.holes.next(steps));
        ASSERT_EQ(steps.size(), 4u);
        EXPECT_EQ(to_string(steps[0]), fmt::format("rapid X{} Y0 Z10", 2 * hole));
        EXPECT_EQ(to_string(steps[2]), fmt::format("feed X{} Y0 Z0 F800", 2 * hole));
    }
    EXPECT_EQ(b.holes.holes_done(), 3);
}

TEST(HoleRun, RepeatCountMustBeAWholeNumberInRange) {
    CycleState st;
    const BlockContext ctx = manual_context();
    for (double k : {-1.0, 2.5, 1e8}) {
        try {
            st.start_block(CycleCode::G81, Words().x(1).z(-5).r(-2).k(k), ctx, CycleConfig{});
            FAIL() << k;
        } catch (const CycleError& e) {
            EXPECT_EQ(std::string(e.what()).rfind("the repeat count K must be a whole number", 0),
                      0u);
        }
    }
    EXPECT_FALSE(st.active());  // a rejected block changes nothing
}

TEST(V54G76, ShiftsByUAndVAtTheCycpFeed) {
    // S1 §3.3: G76 X Y Z R U V P F L — at the bottom dwell, oriented stop, shift U in X and V
    // in Y at the speed parameter CYCP, then retract; back to the centre before the restart.
    CycleState st;
    BlockContext ctx = manual_context();
    CycleConfig cfg;
    cfg.g76_shift_uv = true;
    cfg.g76_shift_feed_mm_min = 120;
    CycleWords w = Words().x(5).y(5).z(-10).r(-5).p(1000);
    w.u_mm = -3;
    w.v_mm = 4;
    EXPECT_EQ(texts(st.run_block(CycleCode::G76, w, ctx, cfg)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "dwell 1s",
                     "spindle orient tip=(0.6 -0.8 0)", "feed X2 Y9 Z-10 F120",
                     "rapid X2 Y9 Z10", "rapid X5 Y5 Z10", "spindle restart"}));
    // U and V are modal like Q; without CYCP the shift uses the cycle's F.
    cfg.g76_shift_feed_mm_min = 0;
    ctx.position_mm = {5, 5, 10};
    const Lines next = texts(st.run_block(std::nullopt, Words().x(20), ctx, cfg));
    ASSERT_GE(next.size(), 6u);
    EXPECT_EQ(next[5], "feed X17 Y9 Z-10 F800");
}

TEST(V54G86, RestartsTheSpindleAtRThenRisesToTheInitialLevel) {
    // C-45: S1 restarts the G86 spindle when the tool is back at R; under G98 the rapid to the
    // initial level follows (the 6th edition restarts only at the return level).
    CycleState st;
    CycleConfig cfg;
    cfg.g86_restart_at_r = true;
    EXPECT_EQ(texts(st.run_block(CycleCode::G86, Words().x(5).y(5).z(-10).r(-5), manual_context(),
                                 cfg)),
              (Lines{"rapid X5 Y5 Z10", "rapid X5 Y5 Z-5", "feed X5 Y5 Z-10 F800", "spindle stop",
                     "rapid X5 Y5 Z-5", "spindle restart", "rapid X5 Y5 Z10"}));
}

}  // namespace
