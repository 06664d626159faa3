// `cnc run`'s error line (the summary's "errors:" and the last line on stderr) for faults motion
// finds after the machine has started: it names the program line the fault is about and its
// cause, as motion sends them on motion.messages, instead of the line that was running and a
// pointer to motion's own message. Figures from configs/sim/mill.ini and the programs, by hand.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cnc_run_harness.hpp"

namespace {

namespace fs = std::filesystem;

using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;

RunResult run_on(const ScratchDir& scratch, const std::string& ini_text, const fs::path& prog) {
    const fs::path ini = scratch.path() / "machine.ini";
    std::ofstream(ini) << ini_text;
    return run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()),
                   scratch.path());
}

fs::path write_program(const ScratchDir& scratch, const std::string& text) {
    const fs::path prog = scratch.path() / "prog.ngc";
    std::ofstream(prog) << text;
    return prog;
}

// The error is the summary's "errors:" field and the last line on stderr, word for word.
void expect_error(const RunResult& r, const std::string& error) {
    EXPECT_EQ(r.exit_code, 1) << r.out;
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos) << r.out;
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), error) << r.out;
    EXPECT_TRUE(r.err.ends_with("\n" + error + "\n")) << r.err;
}

// A fault of the servo function at an action's line (the G906 wait on line 3 times out while
// the machine stands at X10): the line and the cause, no column (motion knows none).
TEST(CncRunErrorSummary, G906TimeoutNamesItsLineAndCause) {
    ScratchDir scratch;
    const fs::path prog =
        write_program(scratch, "G90 G21\nG1 X10 F6000\nG906 PLC[0] LEVEL1 P500\nG1 X20\nM30\n");
    const RunResult r = run_on(scratch, cnc_test::sim_ini("mill"), prog);
    expect_error(r,
                 prog.string() + ":3: G906: motion.digital-in-00 did not become TRUE within 0.5 s");
}

// A fault with no program line of its own (X's simulated positive limit switch moved to
// X = 20, inside the soft limits): the line running when it tripped (2, the move to X30) and
// motion's cause.
TEST(CncRunErrorSummary, LimitSwitchNamesTheRunningLineAndTheSwitch) {
    ScratchDir scratch;
    const fs::path prog = write_program(scratch, "G90 G21\nG1 X30 F3000\nM30\n");
    const std::string ini =
        cnc_test::sim_ini("mill", [](const std::string& section, std::string& line) {
            if (section == "JOINT_0" && line.rfind("SIM_POS_LIMIT_SW = ", 0) == 0)
                line = "SIM_POS_LIMIT_SW = 20";
        });
    const RunResult r = run_on(scratch, ini, prog);
    expect_error(r, prog.string() +
                        ":2: joint 0 hit its positive limit switch (joint.0.pos-lim-sw-in); "
                        "motion stopped, program abandoned");
}

}  // namespace
