// `cnc check`'s summary collector: arc extents include exactly the quadrant points inside the
// sweep, and the length is the arc (helix) length. Numbers worked out by hand on a circle of
// radius 10 about the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "interp/canon_print.hpp"

namespace interp {
namespace {

struct Case {
    SummarySink s;
    void at(double x, double y, double z = 0) { s.emit(Canon{{}, canon::Traverse{{x, y, z}, {}}}); }
    void arc(double x, double y, int turns, double z = 0) {
        canon::Arc a;
        a.end_mm = {x, y, z};
        a.centre_mm = {0, 0, 0};
        a.turns = turns;
        s.emit(Canon{{}, a});
    }
};

constexpr double kPi = std::numbers::pi;

TEST(Summary, QuarterArcCcwHasOnlyItsEnds) {
    Case c;
    c.at(10, 0);
    c.arc(0, 10, 1);
    EXPECT_DOUBLE_EQ(c.s.min_mm()[0], 0);
    EXPECT_DOUBLE_EQ(c.s.max_mm()[0], 10);
    EXPECT_DOUBLE_EQ(c.s.min_mm()[1], 0);
    EXPECT_DOUBLE_EQ(c.s.max_mm()[1], 10);
    EXPECT_NEAR(c.s.feed_length_mm(), 5 * kPi, 1e-9);
}

TEST(Summary, ThreeQuarterArcCwPassesTwoQuadrantPoints) {
    Case c;
    c.at(10, 0);
    c.arc(0, 10, -1);  // through (0,-10) and (-10,0)
    EXPECT_DOUBLE_EQ(c.s.min_mm()[0], -10);
    EXPECT_DOUBLE_EQ(c.s.min_mm()[1], -10);
    EXPECT_DOUBLE_EQ(c.s.max_mm()[1], 10);
    EXPECT_NEAR(c.s.feed_length_mm(), 15 * kPi, 1e-9);
}

TEST(Summary, ArcBetweenQuadrantPointsReachesTheTop) {
    Case c;
    const double h = 10 / std::sqrt(2.0);
    c.at(h, h);
    c.arc(-h, h, 1);  // 45° → 135° CCW, through (0,10) only
    EXPECT_DOUBLE_EQ(c.s.max_mm()[1], 10);  // (min Y is the origin the traverse started from)
    EXPECT_DOUBLE_EQ(c.s.min_mm()[0], -h);
    EXPECT_DOUBLE_EQ(c.s.max_mm()[0], h);
    // The other direction (CW, 45° → 135° the long way) passes +x, -y and -x.
    Case w;
    w.at(h, h);
    w.arc(-h, h, -1);
    EXPECT_DOUBLE_EQ(w.s.max_mm()[0], 10);
    EXPECT_DOUBLE_EQ(w.s.min_mm()[1], -10);
    EXPECT_DOUBLE_EQ(w.s.min_mm()[0], -10);
    EXPECT_DOUBLE_EQ(w.s.max_mm()[1], h);
    EXPECT_NEAR(w.s.feed_length_mm(), 10 * 1.5 * kPi, 1e-9);
}

TEST(Summary, FullCircleAndTwoTurnHelix) {
    Case c;
    c.at(10, 0);
    c.arc(10, 0, 1);
    EXPECT_DOUBLE_EQ(c.s.min_mm()[0], -10);
    EXPECT_DOUBLE_EQ(c.s.min_mm()[1], -10);
    EXPECT_DOUBLE_EQ(c.s.max_mm()[1], 10);
    EXPECT_NEAR(c.s.feed_length_mm(), 20 * kPi, 1e-9);
    Case h;
    h.at(10, 0);
    h.arc(10, 0, 2, -3);  // two turns down 3 mm
    EXPECT_DOUBLE_EQ(h.s.min_mm()[2], -3);
    EXPECT_DOUBLE_EQ(h.s.max_mm()[2], 0);
    EXPECT_NEAR(h.s.feed_length_mm(), std::hypot(40 * kPi, 3), 1e-9);
}

}  // namespace
}  // namespace interp
