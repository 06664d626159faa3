// Kinematics: hand-computed cases and seeded round trips forward(inverse(p)) = p.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "motion/kinematics.hpp"

namespace motion {
namespace {

AxisArray random_axes(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> lin(-500, 500), ang(-360, 360);
    AxisArray p{};
    for (int k = 0; k < kAxes; ++k) p[k] = k >= 3 && k <= 5 ? ang(rng) : lin(rng);
    return p;
}

void expect_round_trip(const Kinematics& kin, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<double> joints(kin.joint_count());
    for (int i = 0; i < 10000; ++i) {
        AxisArray p = random_axes(rng);
        kin.inverse(p, joints);
        AxisArray back = p;
        for (int ax : kin.joint_axes()) back[ax] = 1e300;  // must all be rewritten
        kin.forward(joints, back);
        for (int ax : kin.joint_axes())
            ASSERT_NEAR(back[ax], p[ax], 1e-9 * (1 + std::fabs(p[ax])))
                << kin.name() << " axis " << ax;
    }
}

TEST(Kinematics, TrivialGantryDrivesTwoJointsFromY) {
    TrivialKinematics kin("XYYZ");
    ASSERT_EQ(kin.joint_count(), 4u);
    EXPECT_EQ(std::vector<int>(kin.joint_axes().begin(), kin.joint_axes().end()),
              (std::vector<int>{0, 1, 1, 2}));
    std::vector<double> j(4);
    kin.inverse({1, 2, 3}, j);
    EXPECT_EQ(j, (std::vector<double>{1, 2, 2, 3}));
    expect_round_trip(kin, 1);
}

TEST(Kinematics, TrivialRejectsBadLetters) {
    EXPECT_THROW(TrivialKinematics("XYQ"), std::invalid_argument);
    EXPECT_THROW(TrivialKinematics(""), std::invalid_argument);
    EXPECT_EQ(TrivialKinematics("xyzabc").joint_count(), 6u);
}

TEST(Kinematics, CoreXYMotorsAreSumAndDifference) {
    CoreXYKinematics kin;
    std::vector<double> j(3);
    kin.inverse({10, 3, -1}, j);
    EXPECT_EQ(j, (std::vector<double>{13, 7, -1}));
    AxisArray back{};
    kin.forward(std::vector<double>{13, 7, -1}, back);
    EXPECT_EQ(back[0], 10);
    EXPECT_EQ(back[1], 3);
    expect_round_trip(kin, 2);
}

TEST(Kinematics, TrtTurnsTheWorkpieceWithTheTable) {
    // Pivots at the origin. C = 90 turns the table counter-clockwise seen from +Z: the workpiece
    // point (10, 0, 0) is carried to machine (0, 10, 0).
    XyzacTrtKinematics kin({});
    std::vector<double> j(5);
    kin.inverse({10, 0, 0, 0, 0, 90}, j);
    EXPECT_NEAR(j[0], 0, 1e-12);
    EXPECT_NEAR(j[1], 10, 1e-12);
    EXPECT_NEAR(j[2], 0, 1e-12);
    EXPECT_EQ(j[4], 90);
    // A = 90 tilts about +X: workpiece (0, 10, 0) goes to machine (0, 0, 10).
    kin.inverse({0, 10, 0, 90, 0, 0}, j);
    EXPECT_NEAR(j[1], 0, 1e-12);
    EXPECT_NEAR(j[2], 10, 1e-12);
}

TEST(Kinematics, TrtPivotPointsStayPut) {
    // A point on both rotation axes does not move whatever the angles.
    TrtPivots pv;
    pv.a_pivot_mm = {0, 50, -100};
    pv.c_pivot_mm = {20, 50, -100};
    XyzacTrtKinematics kin(pv);
    std::vector<double> j(5);
    kin.inverse({20, 50, -100, 37, 0, 123}, j);
    EXPECT_NEAR(j[0], 20, 1e-9);
    EXPECT_NEAR(j[1], 50, 1e-9);
    EXPECT_NEAR(j[2], -100, 1e-9);
    // At zero angles workpiece and machine coordinates coincide.
    kin.inverse({1, 2, 3, 0, 0, 0}, j);
    EXPECT_NEAR(j[0], 1, 1e-12);
    EXPECT_NEAR(j[1], 2, 1e-12);
    EXPECT_NEAR(j[2], 3, 1e-12);
    expect_round_trip(kin, 3);
}

TEST(Kinematics, TrtToolTipFollowsTheProgrammedPath) {
    // Moving along a straight workpiece line at fixed angles is a straight machine line too, and
    // distances along it are preserved (the table is rigid).
    TrtPivots pv;
    pv.a_pivot_mm = {0, 10, -50};
    pv.c_pivot_mm = {5, 10, -50};
    XyzacTrtKinematics kin(pv);
    std::vector<double> j0(5), j1(5);
    kin.inverse({0, 0, 0, 30, 0, 45}, j0);
    kin.inverse({3, 4, 0, 30, 0, 45}, j1);
    EXPECT_NEAR(std::hypot(j1[0] - j0[0], j1[1] - j0[1], j1[2] - j0[2]), 5, 1e-12);
}

TEST(Kinematics, FactoryKnowsTheThreeModules) {
    EXPECT_EQ(make_kinematics("trivial", "XYZ")->joint_count(), 3u);
    EXPECT_EQ(make_kinematics("corexy", "")->name(), "corexy");
    EXPECT_EQ(make_kinematics("xyzac-trt", "")->joint_count(), 5u);
    EXPECT_THROW(make_kinematics("scara", ""), std::invalid_argument);
}

}  // namespace
}  // namespace motion
