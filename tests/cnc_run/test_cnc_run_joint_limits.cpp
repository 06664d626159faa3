// `cnc run` on the sim CoreXY with a joint soft limit tighter than the axes allow: motor A
// (joint 0 = X + Y) gets [JOINT_0] MAX_LIMIT = 400 while X and Y keep their 0..300 box. A move
// inside the box can then take joint 0 past 400, which only the check after the inverse
// kinematics catches. Figures from configs/sim/corexy.ini and the programs, by hand.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cnc_run_harness.hpp"

namespace {

namespace fs = std::filesystem;

using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;

// corexy.ini with its HAL files by absolute path and [JOINT_0] MAX_LIMIT = 400.
std::string corexy_ini_with_short_motor_a() {
    return cnc_test::sim_ini("corexy", [](const std::string& section, std::string& line) {
        if (section == "JOINT_0" && line.rfind("MAX_LIMIT = ", 0) == 0) line = "MAX_LIMIT = 400";
    });
}

RunResult run_on_short_corexy(const ScratchDir& scratch, const fs::path& prog) {
    const fs::path ini = scratch.path() / "corexy-short.ini";
    std::ofstream(ini) << corexy_ini_with_short_motor_a();
    return run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()),
                   scratch.path());
}

TEST(CncRunJointLimits, MoveInsideTheAxisBoxPastAJointLimitStopsAtItsLine) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "diag.ngc";
    // Line 3 runs from (150, 150) to (250, 250), inside X, Y 0..300; joint 0 = X + Y passes 400
    // at (200, 200). Joint 1 = X - Y stays 0.
    std::ofstream(prog) << "G90 G21\nG01 X150 Y150 F3000\nG01 X250 Y250\nM30\n";
    const RunResult r = run_on_short_corexy(scratch, prog);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    // At 50 mm/s on the diagonal, X and Y each run 50 / sqrt(2) mm/s, joint 0 twice that:
    // 70.71 mm/s, so the first command past 400 is at most 0.0707 mm past it.
    const std::string head = prog.string() + ":3: joint 0 commanded to ";
    const auto at = r.err.find(head);
    ASSERT_NE(at, std::string::npos) << r.err;
    const double cmd_mm = std::stod(r.err.substr(at + head.size()));
    EXPECT_GT(cmd_mm, 400);
    EXPECT_LE(cmd_mm, 400 + 0.0708);
    EXPECT_NE(r.err.find("mm, beyond its soft limit [0, 400] mm (joint.0.max-limit); motion "
                         "stopped, program abandoned"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos) << r.out;
    // Stopped near (200, 200), not at (250, 250): the fault stop at the axes' 1000 mm/s^2
    // (1414 along the diagonal) from 50 mm/s runs at most 50^2 / 2000 = 1.25 mm of path plus
    // one period (0.05 mm), i.e. under 0.92 mm on each axis; X = Y all the way.
    const auto pos = cnc_test::summary_axes(r.out, "final position (mm)");
    ASSERT_EQ(pos.size(), 3u) << r.out;
    EXPECT_GE(pos[0], 200.0);
    EXPECT_LE(pos[0], 200.0 + 0.92);
    EXPECT_NEAR(pos[1], pos[0], 1e-6);
}

TEST(CncRunJointLimits, PathRidingOnTheJointLimitRunsToTheEnd) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "edge.ngc";
    // (150, 250) and (300, 100) both have X + Y = 400: line 3 keeps joint 0 exactly on its
    // limit all the way, and the corner blend at (150, 250) stays inside the triangle of its
    // corner, where X + Y <= 400. Joint 1 = X - Y runs -100 .. 200, inside -300 .. 300.
    std::ofstream(prog) << "G90 G21\nG01 X150 Y250 F3000\nG01 X300 Y100\nG01 X0 Y0\nM30\n";
    const RunResult r = run_on_short_corexy(scratch, prog);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("soft limit"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 0.0000  y 0.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

}  // namespace
