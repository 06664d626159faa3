// G34–G37 hole positions (S0 §3.7.2). Expected positions computed by hand from
// the manual's word definitions: angles from +X, K > 0 clockwise.

#include "interp/hole_patterns.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cycle_test_util.hpp"

namespace {

using namespace interp::cycles;
using cycle_test::Words;

void expect_holes(const std::vector<Vec2>& got, const std::vector<Vec2>& want) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_NEAR(got[i][0], want[i][0], 1e-9) << "hole " << i;
        EXPECT_NEAR(got[i][1], want[i][1], 1e-9) << "hole " << i;
    }
}

std::string error_of(int g, const PatternWords& w, bool active = true) {
    try {
        hole_pattern(g, w, false, {0, 0}, active);
    } catch (const CycleError& e) {
        return e.what();
    }
    return "no error";
}

TEST(HolePattern, G34ManualExampleTenHolesClockwiseFrom90Degrees) {
    // G34 X10 Y10 I10 J90 K10: centre (10,10), r 10, first hole at 90°, 36° apart, clockwise.
    PatternWords w{10, 10, 10, 90, std::nullopt, 10};
    const auto holes = hole_pattern(34, w, false, {0, 0}, true);
    ASSERT_EQ(holes.size(), 10u);
    EXPECT_NEAR(holes[0][0], 10, 1e-12);
    EXPECT_NEAR(holes[0][1], 20, 1e-12);
    const double a = 54.0 * M_PI / 180.0;  // 90° − 36°
    EXPECT_NEAR(holes[1][0], 10 + 10 * std::cos(a), 1e-12);
    EXPECT_NEAR(holes[1][1], 10 + 10 * std::sin(a), 1e-12);
    EXPECT_NEAR(holes[5][1], 0, 1e-12);  // half way round: straight below the centre
}

TEST(HolePattern, G34NegativeKRunsCounterClockwise) {
    expect_holes(g34_bolt_circle({10, 10}, 10, 0, -4), {{20, 10}, {10, 20}, {0, 10}, {10, 0}});
    expect_holes(g34_bolt_circle({10, 10}, 10, 0, 4), {{20, 10}, {10, 0}, {0, 10}, {10, 20}});
}

TEST(HolePattern, G35LineWithSpacingAngleAndNegativeSpacing) {
    expect_holes(g35_line({1, 2}, 5, 90, 3), {{1, 2}, {1, 7}, {1, 12}});
    expect_holes(g35_line({1, 2}, -5, 0, 3), {{1, 2}, {-4, 2}, {-9, 2}});
}

TEST(HolePattern, G36ArcWithAngularStep) {
    // r 10 about the origin, first at 0°, P30 step, K3 clockwise: 0°, −30°, −60°.
    const double c30 = std::cos(M_PI / 6), s30 = 0.5;
    expect_holes(g36_arc({0, 0}, 10, 0, 30, 3), {{10, 0}, {10 * c30, -10 * s30}, {5, -10 * c30}});
    expect_holes(g36_arc({0, 0}, 10, 0, 90, -2), {{10, 0}, {0, 10}});
}

TEST(HolePattern, G37GridIsSerpentineRowByRow) {
    expect_holes(g37_grid({0, 0}, 10, 3, 5, 2),
                 {{0, 0}, {10, 0}, {20, 0}, {20, 5}, {10, 5}, {0, 5}});
}

TEST(HolePattern, G91MakesTheCentreIncremental) {
    PatternWords w{5, 5, 10, 0, std::nullopt, -4};
    const auto holes = hole_pattern(34, w, true, {100, 100}, true);
    EXPECT_NEAR(holes[0][0], 115, 1e-12);
    EXPECT_NEAR(holes[0][1], 105, 1e-12);
}

TEST(HolePattern, Errors) {
    EXPECT_EQ(error_of(34, {10, 10, 10, 90, std::nullopt, 10}, false),
              "G34/35/36/37 instruction error: special canned cycle mismatch, none specified");
    EXPECT_EQ(error_of(34, {0, 0, 10, 0, std::nullopt, 0}), "G34: the hole count K must not be 0");
    EXPECT_EQ(error_of(36, {0, 0, 10, 0, 5.0, 10000}),
              "G36: the hole count K=10000 is outside -9999…9999");
    EXPECT_EQ(error_of(35, {0, 0, 10, 0, std::nullopt, 0}),
              "G35: the hole count K=0 must be between 1 and 9999");
    EXPECT_EQ(error_of(35, {0, 0, 10, 0, std::nullopt, -3}),
              "G35: the hole count K=-3 must be between 1 and 9999");
    EXPECT_EQ(error_of(37, {0, 0, 10, 5, 0.0, 2}),
              "G37: the hole count P=0 must be between 1 and 9999");
    EXPECT_EQ(error_of(37, {0, 0, 10, 5, 2.5, 2}), "G37: P must be a whole number, got 2.5");
    EXPECT_EQ(error_of(34, {0, 0, std::nullopt, 0, std::nullopt, 3}), "G34: the word I is missing");
    EXPECT_EQ(error_of(38, {0, 0, 1, 0, std::nullopt, 3}),
              "G38 is not a hole-pattern cycle (G34…G37)");
}

TEST(HolePattern, ManualSequenceDrillsThePatternThenOneMoreHole) {
    // S0 §3.7.1: G81 Z-20 R-5 F100 K0 / G34 X10 Y10 I10 J90 K10 / X100.
    CycleState st;
    BlockContext ctx = cycle_test::manual_context();
    ctx.feed_mm_min = 100;
    CycleConfig cfg;
    EXPECT_TRUE(st.run_block(CycleCode::G81, Words().z(-20).r(-5).k(0), ctx, cfg).steps.empty());
    const auto holes =
        hole_pattern(34, {10, 10, 10, 90, std::nullopt, 10}, false, {0, 0}, st.active());
    const Expansion e = st.drill_at(holes, ctx, cfg);
    int feeds = 0;
    for (const auto& s : e.steps) {
        if (const auto* f = std::get_if<Feed>(&s)) {
            ++feeds;
            EXPECT_DOUBLE_EQ(f->to_mm[2], -20);
        }
        if (const auto* r = std::get_if<Rapid>(&s)) {
            EXPECT_GE(r->to_mm[2], -5);  // between holes: rapid
        }
    }
    EXPECT_EQ(feeds, 10);
    // The cycle is still active; "X100" drills one hole unaffected by the pattern.
    ctx.position_mm = cycle_test::end_position(e, ctx.position_mm);
    const auto one = cycle_test::texts(st.run_block(std::nullopt, Words().x(100), ctx, cfg));
    EXPECT_EQ(
        std::count_if(one.begin(), one.end(), [](auto& s) { return s.rfind("feed", 0) == 0; }), 1);
    CycleState none;
    EXPECT_THROW(none.drill_at(holes, ctx, cfg), CycleError);
}

}  // namespace
