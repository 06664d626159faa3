// `cnc run` prints a fault's error line on stderr when it learns the cause, while motion is
// still bringing the machine to rest, not only after the summary: before motion's own message
// (which motion prints at `stop`) and again as the last line. Exit status and summary stay as
// they were. Programs and figures as in test_cnc_run_error_summary.cpp.
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

fs::path write_file(const ScratchDir& scratch, const std::string& name, const std::string& text) {
    const fs::path p = scratch.path() / name;
    std::ofstream(p) << text;
    return p;
}

// X's simulated positive limit switch at X = 20 (inside the soft limits) on configs/sim/mill.
std::string mill_with_limit_switch_at_20() {
    return cnc_test::sim_ini("mill", [](const std::string& section, std::string& line) {
        if (section == "JOINT_0" && line.rfind("SIM_POS_LIMIT_SW = ", 0) == 0)
            line = "SIM_POS_LIMIT_SW = 20";
    });
}

// The whole of stderr: the error line as soon as motion's end record names the cause, motion's
// message at stop, the error line after the summary. The old `cnc run` printed only the last
// two.
TEST(CncRunFaultLive, G906TimeoutErrorLineComesFirst) {
    ScratchDir scratch;
    const fs::path ini = write_file(scratch, "machine.ini", cnc_test::sim_ini("mill"));
    const fs::path prog = write_file(
        scratch, "prog.ngc", "G90 G21\nG1 X10 F6000\nG906 PLC[0] LEVEL1 P500\nG1 X20\nM30\n");
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()), scratch.path());
    const std::string error =
        prog.string() + ":3: G906: motion.digital-in-00 did not become TRUE within 0.5 s";
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), error) << r.out;
    EXPECT_EQ(r.err, error + "\nmotion.0: " + error + "\n" + error + "\n");
}

// A fault that names no line: the line running when it tripped (2) and motion's cause, first
// while the machine stops.
TEST(CncRunFaultLive, LimitSwitchErrorLineComesFirst) {
    ScratchDir scratch;
    const fs::path ini = write_file(scratch, "machine.ini", mill_with_limit_switch_at_20());
    const fs::path prog = write_file(scratch, "prog.ngc", "G90 G21\nG1 X30 F3000\nM30\n");
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()), scratch.path());
    const std::string cause =
        "joint 0 hit its positive limit switch (joint.0.pos-lim-sw-in); motion stopped, program "
        "abandoned";
    const std::string error = prog.string() + ":2: " + cause;
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), error) << r.out;
    EXPECT_EQ(r.err, error + "\nmotion.0: " + cause + "\n" + error + "\n");
}

// The same on the real-time clock (threads running on their own, the loop draining the cycle
// stream): the error line before motion's message. Only the order is checked: a loaded
// machine may add a warning about cycles not sampled.
TEST(CncRunFaultLive, RealTimeErrorLineComesBeforeMotionsMessage) {
    ScratchDir scratch;
    const fs::path ini = write_file(scratch, "machine.ini", mill_with_limit_switch_at_20());
    const fs::path prog = write_file(scratch, "prog.ngc", "G90 G21\nG1 X30 F3000\nM30\n");
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}'", ini.string(), prog.string()), scratch.path());
    const std::string error =
        prog.string() +
        ":2: joint 0 hit its positive limit switch (joint.0.pos-lim-sw-in); motion stopped, "
        "program abandoned";
    EXPECT_EQ(r.exit_code, 1);
    const auto live = r.err.find(error + "\n");
    const auto motion = r.err.find("motion.0: joint 0 hit its positive limit switch");
    ASSERT_NE(live, std::string::npos) << r.err;
    ASSERT_NE(motion, std::string::npos) << r.err;
    EXPECT_LT(live, motion) << r.err;
    EXPECT_TRUE(r.err.ends_with("\n" + error + "\n")) << r.err;
}

}  // namespace
