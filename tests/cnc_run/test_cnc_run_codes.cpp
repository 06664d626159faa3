// `cnc run` on the sim mill with NcStudio's machine-side program codes: the rapid rate of F in
// a G00 block, M801 messages and warnings shown to the user. The figures come from
// configs/sim/mill.ini (X: 100 mm/s, 1000 mm/s^2, 20000 mm/s^3) and the programs, by hand.
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

RunResult run_on_mill(const ScratchDir& scratch, const std::string& program,
                      const std::string& extra_args = "") {
    const fs::path prog = scratch.path() / "prog.ngc";
    std::ofstream(prog) << program;
    return run_cnc(
        fmt::format("configs/sim/mill.ini '{}' --sim-clock {}", prog.string(), extra_args),
        scratch.path());
}

TEST(CncRunCodes, G00WithFRunsAtTheProgrammedRapidRate) {
    ScratchDir scratch;
    const RunResult r = run_on_mill(scratch, "G90 G21\nG00 X100 F600\nM30\n");
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    // why: F600 in a G00 block caps the rapid at 10 mm/s (the axis allows 100 mm/s).
    EXPECT_NEAR(cnc_test::summary_axes(r.out, "max velocity (mm/s)").at(0), 10, 1e-3) << r.out;
    // why: a jerk-limited start to v (and the stop from it) that never reaches the acceleration
    // limit takes 2 sqrt(v / j) and covers v sqrt(v / j), so the move takes L / v + 2 sqrt(v / j)
    // = 10 + 2 sqrt(10 / j) s: 10.0447 s at j = 20000 mm/s^3, 10.0449 s with the planner's
    // 1 % reserve (19800). At the axis maximum it would be about 1.16 s.
    EXPECT_NEAR(cnc_test::summary_number(r.out, "motion time"), 10.045, 0.005) << r.out;
}

TEST(CncRunCodes, G00RapidRateAboveTheAxisLimitRunsAtTheLimit) {
    ScratchDir scratch;
    const RunResult r = run_on_mill(scratch, "G90 G21\nG00 Z-60 F6000\nM30\n");
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    // why: F6000 is 100 mm/s; Z allows 50 mm/s.
    EXPECT_NEAR(cnc_test::summary_axes(r.out, "max velocity (mm/s)").at(2), 50, 1e-3) << r.out;
}

// The message is printed on a line of its own when the machine reaches it (X10, about 1.02 s
// into the run: between the progress lines of 1 s and 2 s); warnings go to stderr, once per
// unhandled M802 code.
TEST(CncRunCodes, M801IsPrintedWhenReachedAndWarningsOnce) {
    ScratchDir scratch;
    const RunResult r =
        run_on_mill(scratch,
                    "G90 G21\nG1 X10 F600\nM801 MSG \"tool 2: check the clamp\"\nG1 X20\n"
                    "M802 P12345\nM802 P12345\nM10\nM30\n");
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    const std::string prog = (scratch.path() / "prog.ngc").string();
    const auto message = r.out.find("\n" + prog + ":3: message: tool 2: check the clamp\n");
    const auto before = r.out.find("progress:     1.0 s");
    const auto after = r.out.find("progress:     2.0 s");
    ASSERT_NE(message, std::string::npos) << r.out;
    ASSERT_NE(before, std::string::npos) << r.out;
    ASSERT_NE(after, std::string::npos) << r.out;
    EXPECT_LT(before, message) << r.out;
    EXPECT_LT(message, after) << r.out;
    const std::string warning =
        prog +
        ":5:1: warning: M802 P12345: this machine has no handler for that integer message; "
        "ignored\n";
    const auto first = r.err.find(warning);
    EXPECT_NE(first, std::string::npos) << r.err;
    EXPECT_EQ(r.err.find(warning, first + 1), std::string::npos) << r.err;  // once
    EXPECT_NE(r.err.find(prog + ":7:1: warning: M10 is an invalid instruction in NcStudio 6th "
                                "edition; ignored\n"),
              std::string::npos)
        << r.err;
}

// M902 H0 at X10 makes that point X0 without moving: the drives (wired from motion's joint
// commands) must not see the coordinate jump, and the summary counts only real motion.
TEST(CncRunCodes, M902SetsTheMachineCoordinateWithoutMovingTheDrives) {
    ScratchDir scratch;
    const RunResult r =
        run_on_mill(scratch, "G90 G21\nG1 X10 F600\nG906\nM902 H0\nG1 X5\nM30\n");
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    EXPECT_NE(r.out.find("errors: none"), std::string::npos) << r.out;
    // why: X10 became X0, so X5 is 5 mm further on, at machine X5 (motor at 15).
    EXPECT_NEAR(cnc_test::summary_axes(r.out, "final position (mm)").at(0), 5, 1e-4) << r.out;
    // why: 10 mm, then 5 mm; the 10 mm jump of the coordinate is neither path nor speed.
    EXPECT_NEAR(cnc_test::summary_number(r.out, "path length"), 15, 1e-3) << r.out;
    EXPECT_NEAR(cnc_test::summary_axes(r.out, "max velocity (mm/s)").at(0), 10, 1e-3) << r.out;
}

}  // namespace
