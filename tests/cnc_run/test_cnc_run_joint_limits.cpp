// `cnc run` with joint soft limits that only the kinematics can see: a move inside the axis
// box that would take a motor past its travel is refused at its line, before it starts (the
// planner thread maps the path through the kinematics); the machine stops at rest where the
// move before ended. Figures from configs/sim/{corexy,5axis-trt}.ini and the programs, by hand.
//
// CoreXY: motor A (joint 0 = X + Y) gets [JOINT_0] MAX_LIMIT = 400 while X and Y keep their
// 0..300 box. 5axis-trt: the A axis runs parallel to X through Y = 0, Z = -80 ([KINS]
// Z_ROT_POINT); a workpiece point p is carried to machine y = y cos A - (z + 80) sin A,
// z = y sin A + (z + 80) cos A - 80 at C = 0; machine Z (joint 2) ends at 0.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
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

RunResult run_on(const ScratchDir& scratch, const std::string& ini_text, const fs::path& prog,
                 const std::string& extra = "") {
    const fs::path ini = scratch.path() / "machine.ini";
    std::ofstream(ini) << ini_text;
    return run_cnc(fmt::format("'{}' '{}' --sim-clock {}", ini.string(), prog.string(), extra),
                   scratch.path());
}

fs::path write_program(const ScratchDir& scratch, const std::string& name,
                       const std::string& text) {
    const fs::path prog = scratch.path() / name;
    std::ofstream(prog) << text;
    return prog;
}

TEST(CncRunJointLimits, MoveInsideTheAxisBoxPastAJointLimitIsRefusedAtItsLine) {
    ScratchDir scratch;
    // Line 3 runs from (150, 150) to (250, 250), inside X, Y 0..300; joint 0 = X + Y would end at
    // 500, past 400. The whole program is planned before the machine starts, so nothing moves.
    const fs::path prog =
        write_program(scratch, "diag.ngc", "G90 G21\nG01 X150 Y150 F3000\nG01 X250 Y250\nM30\n");
    const RunResult r = run_on(scratch, corexy_ini_with_short_motor_a(), prog);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.err.find(prog.string() +
                         ":3:1: joint 0 would move to 500 mm (axis position X250 Y250 Z0), beyond "
                         "its soft limit [0, 400] mm (joint.0.max-limit); the move is refused "
                         "before it starts"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("commanded to"), std::string::npos) << r.err;  // no servo-time trip
    EXPECT_EQ(r.out.find("motion time"), std::string::npos) << r.out;   // never started
}

TEST(CncRunJointLimits, RefusedMoveStopsTheMachineAtRestWhereTheMoveBeforeEnded) {
    ScratchDir scratch;
    // Line 3 reads the machine position: the interpreter waits for the machine to get there,
    // so the run starts with only line 2 planned and line 4 is refused while the machine moves.
    const fs::path prog =
        write_program(scratch, "diag.ngc",
                      "G90 G21\nG01 X150 Y150 F3000\n#1 = #CURMACHPOS.X\nG01 X250 Y250\nM30\n");
    const fs::path trace = scratch.path() / "trace.csv";
    const RunResult r =
        run_on(scratch, corexy_ini_with_short_motor_a(), prog, "--trace '" + trace.string() + "'");
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.err.find(prog.string() + ":4:1: joint 0 would move to 500 mm"), std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("commanded to"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos) << r.out;
    // The summary and cnc's line on stderr (its only one) name the refused line 4 and why, not
    // line 2, which was running when the planner thread found it (the same move as in the test
    // above).
    const std::string refused = prog.string() +
                                ":4:1: joint 0 would move to 500 mm (axis position X250 Y250 Z0), "
                                "beyond its soft limit [0, 400] mm (joint.0.max-limit); the move "
                                "is refused before it starts";
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), refused) << r.out;
    EXPECT_EQ(r.err, refused + "\n");
    // At rest at the end of line 2, (150, 150): joint 0 at 300.
    EXPECT_NE(r.out.find("\nfinal position (mm): x 150.0000  y 150.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
    std::string header;
    const auto rows = cnc_test::csv_rows(cnc_test::slurp(trace), header);
    ASSERT_EQ(header, "t,line,x,y,z,j0,j1,j2,vel");
    ASSERT_GT(rows.size(), 100u);
    double max_j0 = 0, max_line = 0;
    for (const auto& row : rows) {
        max_j0 = std::max(max_j0, row[5]);
        max_line = std::max(max_line, row[1]);
    }
    EXPECT_NEAR(max_j0, 300, 1e-9);
    EXPECT_LE(max_line, 3);                 // line 4 never started
    EXPECT_NEAR(rows.back()[8], 0, 1e-12);  // standing still at the end
}

TEST(CncRunJointLimits, PathRidingOnTheJointLimitRunsToTheEnd) {
    ScratchDir scratch;
    // (150, 250) and (300, 100) both have X + Y = 400: line 3 keeps joint 0 exactly on its
    // limit all the way, and the corner blend at (150, 250) stays inside the triangle of its
    // corner, where X + Y <= 400. Joint 1 = X - Y runs -100 .. 200, inside -300 .. 300.
    const fs::path prog = write_program(scratch, "edge.ngc",
                                        "G90 G21\nG01 X150 Y250 F3000\nG01 X300 Y100\nG01 X0 "
                                        "Y0\nM30\n");
    const RunResult r = run_on(scratch, corexy_ini_with_short_motor_a(), prog);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("soft limit"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 0.0000  y 0.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

TEST(CncRunJointLimits, ArcWhoseEndsAreInsideButWhoseMiddleCrossesTheLimitIsRefused) {
    ScratchDir scratch;
    // Line 3: the quarter circle about (150, 150), radius 100, from (250, 150) to (150, 250).
    // Both ends have X + Y = 400, on motor A's limit; in between X + Y = 300 + 100 (cos t +
    // sin t) reaches 300 + 100 sqrt 2 = 441.42 at 45 degrees. X and Y stay within 150..250.
    const fs::path prog = write_program(
        scratch, "arc.ngc", "G90 G21\nG01 X250 Y150 F3000\nG03 X150 Y250 I-100 J0\nM30\n");
    const RunResult r = run_on(scratch, corexy_ini_with_short_motor_a(), prog);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    // The message names the farthest point: 45 degrees, (150 + 50 sqrt 2, 150 + 50 sqrt 2).
    EXPECT_NE(r.err.find(prog.string() +
                         ":3:1: joint 0 would move to 441.4214 mm (axis position X220.7107 "
                         "Y220.7107 Z0), beyond its soft limit [0, 400] mm (joint.0.max-limit)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out.find("motion time"), std::string::npos) << r.out;  // never started
}

TEST(CncRunJointLimits, ArcTouchingTheLimitFromInsideRunsToTheEnd) {
    ScratchDir scratch;
    // Line 3: the quarter circle about (150, 150), radius 70.710678 (100 / sqrt 2 rounded down),
    // from (220.710678, 150) to (150, 220.710678): X + Y reaches 300 + 70.710678 sqrt 2 =
    // 399.9999996 at 45 degrees, 0.4 um inside motor A's limit; its ends are at 370.71.
    const fs::path prog = write_program(scratch, "touch.ngc",
                                        "G90 G21\nG01 X220.710678 Y150 F3000\n"
                                        "G03 X150 Y220.710678 I-70.710678 J0\nG01 X0 Y0\nM30\n");
    const RunResult r = run_on(scratch, corexy_ini_with_short_motor_a(), prog);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("soft limit"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 0.0000  y 0.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

// 5axis-trt.ini with its HAL files by absolute path, one [JOINT_N] key changed if given.
std::string trt_ini(const std::string& joint = "", const std::string& key = "",
                    const std::string& value = "") {
    return cnc_test::sim_ini("5axis-trt", [&](const std::string& section, std::string& line) {
        if (section == joint && line.rfind(key + " = ", 0) == 0) line = key + " = " + value;
    });
}

TEST(CncRunJointLimits, TiltCarryingTheWorkpieceAboveMachineZIsRefused) {
    ScratchDir scratch;
    // Line 3 tilts A to 60 (inside [AXIS_A] -90..90) with the tool at workpiece (0, 100, -80),
    // 100 mm from the A axis along Y: machine z = 100 sin A - 80 passes 0 at A = 53.13 and would
    // end at 100 sin 60 - 80 = 6.6025, past joint 2's max-limit 0. Every axis stays in its box.
    const fs::path prog =
        write_program(scratch, "tilt.ngc", "G90 G21\nG01 X0 Y100 Z-80 F3000\nG01 A60\nM30\n");
    const RunResult r = run_on(scratch, trt_ini(), prog);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.err.find(prog.string() +
                         ":3:1: joint 2 would move to 6.6025 mm (axis position X0 Y100 Z-80 A60 "
                         "C0), beyond its soft limit [-200, 0] mm (joint.2.max-limit); the move "
                         "is refused before it starts"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out.find("motion time"), std::string::npos) << r.out;
}

TEST(CncRunJointLimits, TiltThatStaysBelowMachineZRunsToTheEnd) {
    ScratchDir scratch;
    // As above to A = 50: machine z = 100 sin 50 - 80 = -3.4 at most, inside; back to A = 0.
    const fs::path prog = write_program(scratch, "tilt.ngc",
                                        "G90 G21\nG01 X0 Y100 Z-80 F3000\nG01 A50\nG01 A0\nM30\n");
    const RunResult r = run_on(scratch, trt_ini(), prog);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("soft limit"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nresult: finished\n"), std::string::npos) << r.out;
}

TEST(CncRunJointLimits, TiltPastTheTrunnionMotorsLimitIsRefused) {
    ScratchDir scratch;
    // [JOINT_3] MAX_LIMIT = 45: the A motor (joint 3 = A) cannot follow line 2's A60, although
    // [AXIS_A] allows up to 90.
    const fs::path prog = write_program(scratch, "tilt.ngc", "G90 G21\nG01 A60 F3000\nM30\n");
    const RunResult r = run_on(scratch, trt_ini("JOINT_3", "MAX_LIMIT", "45"), prog);
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.err.find(prog.string() +
                         ":2:1: joint 3 would move to 60 deg (axis position X0 Y0 Z0 A60 C0), "
                         "beyond its soft limit [-100, 45] deg (joint.3.max-limit)"),
              std::string::npos)
        << r.err;
}

}  // namespace
