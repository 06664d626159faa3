// XyzacTrtKinematics with a tool: seeded property tests.
//
// The program's end points are the spindle nose: tip + L along the workpiece Z (G43 adds the
// tool length L to Z). The tool hangs from the nose along the machine Z, so the tool tip is
// at nose - L z in machine coordinates. It follows the path when that point is exactly where
// the tables carry the programmed tip: M(tip) with the plain pivots. The kinematics gets the
// tool length by adding it to the A pivot's Z (kins_xyzac_trt's tool-offset pin).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "motion/kinematics.hpp"

namespace motion {
namespace {

struct Machine {
    TrtPivots plain;  // the table geometry
    double tool_mm;   // tool length L
    TrtPivots with_tool() const {
        TrtPivots p = plain;
        p.a_pivot_mm.z() += tool_mm;
        return p;
    }
};

Machine random_machine(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> off(-100, 100), tool(0, 150);
    Machine m;
    m.plain.c_pivot_mm = {off(rng), off(rng), 0.0};
    m.plain.a_pivot_mm = {0.0, off(rng), off(rng) - 100};
    m.tool_mm = tool(rng);
    return m;
}

AxisArray random_tip(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> lin(-200, 200), a(-120, 120), c(-720, 720);
    AxisArray p{};
    p[0] = lin(rng);
    p[1] = lin(rng);
    p[2] = lin(rng);
    p[3] = a(rng);
    p[5] = c(rng);
    return p;
}

Eigen::Vector3d linear(const std::vector<double>& j) {
    return {j[0], j[1], j[2]};
}

// Where the machine puts the tool tip for the program point `tip` (nose = tip + L z).
Eigen::Vector3d tool_tip_machine(const Machine& m, const AxisArray& tip, double tool_in_kins) {
    TrtPivots pv = m.plain;
    pv.a_pivot_mm.z() += tool_in_kins;
    XyzacTrtKinematics kin(pv);
    AxisArray nose = tip;
    nose[2] += m.tool_mm;  // what G43 makes of the programmed Z
    std::vector<double> j(5);
    kin.inverse(nose, j);
    return linear(j) - m.tool_mm * Eigen::Vector3d::UnitZ();
}

// Where the tables carry the workpiece point `tip`.
Eigen::Vector3d table_point_machine(const Machine& m, const AxisArray& tip) {
    XyzacTrtKinematics kin(m.plain);
    std::vector<double> j(5);
    kin.inverse(tip, j);
    return linear(j);
}

TEST(TrtToolTip, RoundTripWithToolLength) {
    std::mt19937_64 rng(51);
    for (int i = 0; i < 20000; ++i) {
        const Machine m = random_machine(rng);
        XyzacTrtKinematics kin(m.with_tool());
        const AxisArray p = random_tip(rng);
        std::vector<double> j(5);
        kin.inverse(p, j);
        AxisArray back{};
        kin.forward(j, back);
        for (int ax : kin.joint_axes())
            ASSERT_NEAR(back[ax], p[ax], 1e-9 * (1 + std::fabs(p[ax]))) << "case " << i;
    }
}

TEST(TrtToolTip, TipIsWhereTheTablesCarryTheProgrammedPoint) {
    std::mt19937_64 rng(52);
    for (int i = 0; i < 20000; ++i) {
        const Machine m = random_machine(rng);
        const AxisArray tip = random_tip(rng);
        const Eigen::Vector3d error =
            tool_tip_machine(m, tip, m.tool_mm) - table_point_machine(m, tip);
        ASSERT_LT(error.norm(), 1e-9) << "case " << i;
    }
}

// Along a programmed straight line with A and C turning, every sampled tip stays on the
// table-carried line: the property motion relies on between its period samples.
TEST(TrtToolTip, TipFollowsAToolpathWhileTheTablesTurn) {
    std::mt19937_64 rng(53);
    for (int path = 0; path < 200; ++path) {
        const Machine m = random_machine(rng);
        const AxisArray from = random_tip(rng), to = random_tip(rng);
        for (int k = 0; k <= 100; ++k) {
            const double s = k / 100.0;
            AxisArray tip{};
            for (int ax = 0; ax < kAxes; ++ax) tip[ax] = from[ax] + s * (to[ax] - from[ax]);
            const Eigen::Vector3d error =
                tool_tip_machine(m, tip, m.tool_mm) - table_point_machine(m, tip);
            ASSERT_LT(error.norm(), 1e-9) << "path " << path << " s " << s;
        }
    }
}

// Without the tool length in the kinematics the tip misses by L |Ra z - z| = 2 L sin(A/2):
// the case the tool-offset pin exists for (and proof the checks above can fail).
TEST(TrtToolTip, WithoutToolOffsetTheTipMissesByTheTilt) {
    Machine m;
    m.plain.a_pivot_mm = {0, 0, -80};
    m.tool_mm = 40;
    AxisArray tip{};
    tip[0] = 10;
    tip[1] = 5;
    tip[2] = -10;
    tip[3] = 30;
    tip[5] = 90;
    const double miss = (tool_tip_machine(m, tip, 0.0) - table_point_machine(m, tip)).norm();
    EXPECT_NEAR(miss, 2 * 40 * std::sin(15 * std::numbers::pi / 180), 1e-9);  // 20.706 mm
    tip[3] = 0;  // level table: the tool length needs no kinematics
    EXPECT_LT((tool_tip_machine(m, tip, 0.0) - table_point_machine(m, tip)).norm(), 1e-12);
}

}  // namespace
}  // namespace motion
