// `cnc run` on a CoreXY machine whose motors, not its axes, are the limit: configs/sim/corexy.ini
// with motors A (joint 0 = X + Y) and B (joint 1 = X - Y) at 100 mm/s and 1000 mm/s^2, the
// figures of one axis, while X and Y keep 100 mm/s and 1000 mm/s^2 each (X + Y could ask 200
// and 2000 of a motor). The planner keeps every motor within its limits: axis-parallel moves
// run at the full axis speed, diagonal ones sqrt 2 slower, and no motor excess is reported at
// the end. Figures by hand in the tests; motion time counts the periods until motion reports
// done, 2 ms after the move's last period (measured on the X move, whose time does not depend
// on the motors).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "cnc_run_harness.hpp"

namespace {

namespace fs = std::filesystem;

using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;
using cnc_test::summary_axes;
using cnc_test::summary_number;

constexpr double kDoneLagS = 0.002;  // motion time after the last moving period
constexpr double kPeriodS = 0.001;

// corexy.ini with its HAL files by absolute path, motors A and B at one axis's figures (jerk as
// given, 0 = unlimited), the axes' jerk as given.
std::string corexy_with_slow_motors(const std::string& axis_jerk, const std::string& motor_jerk) {
    return cnc_test::sim_ini("corexy", [&](const std::string& section, std::string& line) {
        const bool ab = section == "JOINT_0" || section == "JOINT_1";
        if (section.rfind("AXIS_", 0) == 0 && line.rfind("MAX_JERK = ", 0) == 0)
            line = "MAX_JERK = " + axis_jerk;
        if (section == "JOINT_2" && line.rfind("MAX_JERK = ", 0) == 0)
            line = "MAX_JERK = " + axis_jerk;
        if (!ab) return;
        if (line.rfind("MAX_VELOCITY = ", 0) == 0) line = "MAX_VELOCITY = 100";
        if (line.rfind("MAX_ACCELERATION = ", 0) == 0) line = "MAX_ACCELERATION = 1000";
        if (line.rfind("MAX_JERK = ", 0) == 0) line = "MAX_JERK = " + motor_jerk;
    });
}

RunResult run_on(const ScratchDir& scratch, const std::string& ini_text, const fs::path& prog) {
    const fs::path ini = scratch.path() / "machine.ini";
    std::ofstream(ini) << ini_text;
    return run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()),
                   scratch.path());
}

RunResult run_text(const ScratchDir& scratch, const std::string& ini_text,
                   const std::string& program) {
    const fs::path prog = scratch.path() / "prog.ngc";
    std::ofstream(prog) << program;
    return run_on(scratch, ini_text, prog);
}

void expect_no_motor_excess(const RunResult& r) {
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_EQ(r.err.find("was commanded"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("errors: none"), std::string::npos) << r.out;
}

TEST(CncRunCoreXYMotors, ADiagonalRunsAtTheMotorLimitsOverSqrt2) {
    ScratchDir scratch;
    // 282.843 mm at 45 degrees: motor A turns at sqrt 2 times the path speed, so the path runs at
    // v = 100 / sqrt 2 = 70.711 mm/s and accelerates at a = 990 / sqrt 2 = 700.04 mm/s^2 (1 %
    // reserve, no jerk limit): L / v + v / a = 4 + 0.10101 = 4.10101 s. X and Y each at
    // v / sqrt 2 = 50 mm/s and a / sqrt 2 = 495 mm/s^2. (Planned with the axis limits alone it
    // took 2.10101 s, the path at 141 mm/s and motor A = X + Y at 200 mm/s.)
    const RunResult r = run_text(scratch, corexy_with_slow_motors("0", "0"),
                                 "G90 G21\nG01 X200 Y200 F12000\nM30\n");
    expect_no_motor_excess(r);
    EXPECT_NEAR(summary_number(r.out, "motion time"), 4.10101 + kDoneLagS, kPeriodS) << r.out;
    const auto vel = summary_axes(r.out, "max velocity (mm/s)");
    const auto acc = summary_axes(r.out, "max acceleration (mm/s^2)");
    ASSERT_EQ(vel.size(), 3u) << r.out;
    ASSERT_EQ(acc.size(), 3u) << r.out;
    EXPECT_NEAR(vel[0], 50, 1e-3);
    EXPECT_NEAR(vel[1], 50, 1e-3);
    EXPECT_NEAR(acc[0], 495, 0.1);
}

TEST(CncRunCoreXYMotors, AnXMoveRunsAtTheFullAxisSpeed) {
    ScratchDir scratch;
    // Along X both motors turn at the path speed: 200 mm at 100 mm/s with 990 mm/s^2 ramps,
    // 2 + 0.10101 s, as on a machine without motor limits.
    const RunResult r =
        run_text(scratch, corexy_with_slow_motors("0", "0"), "G90 G21\nG01 X200 F12000\nM30\n");
    expect_no_motor_excess(r);
    EXPECT_NEAR(summary_number(r.out, "motion time"), 2.10101 + kDoneLagS, kPeriodS) << r.out;
    const auto vel = summary_axes(r.out, "max velocity (mm/s)");
    ASSERT_EQ(vel.size(), 3u) << r.out;
    EXPECT_NEAR(vel[0], 100, 1e-3);
}

TEST(CncRunCoreXYMotors, APocketWithJerkLimitsReportsNoMotorExcess) {
    ScratchDir scratch;
    // examples/pocket.ngc (lines, arcs, rapids, blended corners) with the axes and the motors
    // jerk limited (motors at 20000 mm/s^3, X + Y could ask 40000): motion checks every motor's
    // commanded velocity and acceleration each period and reports any excess at the end.
    const RunResult r = run_on(scratch, corexy_with_slow_motors("20000", "20000"),
                               fs::path(CNC_SOURCE_DIR) / "examples/pocket.ngc");
    expect_no_motor_excess(r);
    EXPECT_NE(r.out.find("result: finished"), std::string::npos) << r.out;
}

TEST(CncRunCoreXYMotors, ANegativeMotorLimitIsRefusedBeforeAnythingMoves) {
    ScratchDir scratch;
    std::string ini =
        cnc_test::sim_ini("corexy", [](const std::string& section, std::string& line) {
            if (section == "JOINT_0" && line.rfind("MAX_ACCELERATION = ", 0) == 0)
                line = "MAX_ACCELERATION = -5";
        });
    const RunResult r = run_text(scratch, ini, "G90 G21\nG01 X10 F600\nM30\n");
    EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("motion.0: joint.0.max-acceleration = -5: a joint limit must be >= 0 "
                         "(0 = unlimited)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.out.find("motion time"), std::string::npos) << r.out;  // never started
}

}  // namespace
