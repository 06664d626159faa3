// `cnc run` on the sim mill with the machine's I/O: outputs synchronised with motion (M901), the
// spindle at-speed wait, and a tool setter touched by G904. The figures come from the mill's
// INI (Z: 500 mm/s^2) and the programs, by hand.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cnc_run_harness.hpp"

namespace {

namespace fs = std::filesystem;

using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;
using cnc_test::slurp;

// configs/sim/mill.ini with its HAL files named by absolute path, plus `extra_hal` loaded last.
std::string mill_ini_plus(const fs::path& extra_hal) {
    return cnc_test::sim_ini("mill", [&](const std::string&, std::string& line) {
        if (line.rfind("HALFILE = ", 0) == 0 && line.find("io-loopback.hal") != std::string::npos)
            line += "\nHALFILE = " + extra_hal.string();
    });
}

// configs/sim/mill.ini with a tool setter (cnc_test::tool_setter_hal) closing below Z `z_mm`.
fs::path tool_setter_ini(const fs::path& dir, double z_mm) {
    const fs::path ini = dir / "setter.ini";
    std::ofstream(ini) << mill_ini_plus(cnc_test::tool_setter_hal(dir, z_mm));
    return ini;
}

std::vector<double> final_position(const std::string& out) {
    return cnc_test::summary_axes(out, "final position (mm)");
}

// The S0 §3.5.3 tool-setting routine's moves: G904 down to the setter, then an incremental lift
// measured from where the switch closed (the trip point; Z stops a braking distance below
// it), and a read of the point reached.
TEST(CncRunIo, ToolSetterG904StopsAtTheSwitchAndTheProgramGoesOnFromThere) {
    ScratchDir scratch;
    const fs::path ini = tool_setter_ini(scratch.path(), -12.5);
    const fs::path prog = scratch.path() / "setter.ngc";
    std::ofstream(prog) << "G90 G21\nG0 X10 Y10\nG0 Z-5\nG904 FZ-300 PZ3 LZ1 Z50\n"
                           "G91 G0 Z5\nG90\n#1 = #CURMACHPOS.Z\nG0 X=20+#1\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()), scratch.path());
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    const std::vector<double> pos = final_position(r.out);
    ASSERT_EQ(pos.size(), 3u) << r.out;
    // why: from Z-5 the jog ramps to 5 mm/s in 10 periods (0.025 mm at 500 mm/s^2), then moves
    // 5 um a period: Z = -5.025 - 0.005 k. At k = 1495 it is -12.5 exactly, where the comparator
    // (out = in1 > in0) stays FALSE; at -12.505 it closes, motion sees it in the next period,
    // latches the trip point -12.505 (the command of the period before) and brakes from 5 mm/s:
    // 10 periods of 4.75, 4.25 ... 0.25 um = 0.025 mm, so Z stops at -12.530. The interpreter
    // takes the trip point: the lift of 5 mm ends at -7.505; #CURMACHPOS.Z reads that point,
    // so X = 20 + Z.
    EXPECT_NEAR(pos[2], -7.505, 1e-4);
    EXPECT_NEAR(pos[0], 20 + pos[2], 1e-4);
    EXPECT_NEAR(pos[1], 10, 1e-9);
}

// S0 §3.5.3's floating tool-setting routine (FEATURES TSET-1) as the sim mill runs it through
// the interp component: look-ahead closed, a message while Z goes down, the message cleared,
// look-ahead open, the lift at 100 % override measured from the touch.
TEST(CncRunIo, ToolSettingRoutineShowsItsMessagesAndLiftsFromTheTouch) {
    ScratchDir scratch;
    const fs::path ini = tool_setter_ini(scratch.path(), -12.5);
    const fs::path prog = scratch.path() / "tset.ngc";
    std::ofstream(prog) << "G90 G21\nG0 X10 Y10\nG0 Z-5\nM802 P196609\n"
                           "M801 MSG \"|D|waiting for tool-setting signal\"\n"
                           "G904 FZ-300 PZ3 LZ1 Z50\nM801 MSG \"\"\nM802 P196608\n"
                           "G903 G00 G91 Z5\nG90\n#1 = #CURMACHPOS.Z\nG0 X=20+#1\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()), scratch.path());
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    // why: as in ToolSetterG904StopsAtTheSwitch...: the switch closes at Z -12.505 (the trip
    // point), Z stops at -12.530, the lift ends 5 mm above the trip point.
    const std::vector<double> pos = final_position(r.out);
    ASSERT_EQ(pos.size(), 3u) << r.out;
    EXPECT_NEAR(pos[2], -7.505, 1e-4);
    EXPECT_NEAR(pos[0], 12.495, 1e-4);
    // why: the first message is due before the G904 starts (about 0.3 s: the rapids), the
    // second when Z has stopped (the G904 runs 7.5 mm at 5 mm/s: past 1.5 s), so the progress
    // line of 1 s comes between them.
    const auto waiting =
        r.out.find(prog.string() + ":5: message: |D|waiting for tool-setting signal\n");
    const auto one_s = r.out.find("progress:     1.0 s");
    const auto cleared = r.out.find(prog.string() + ":7: message: (cleared)\n");
    ASSERT_NE(waiting, std::string::npos) << r.out;
    ASSERT_NE(cleared, std::string::npos) << r.out;
    EXPECT_LT(waiting, one_s) << r.out;
    EXPECT_LT(one_s, cleared) << r.out;
}

TEST(CncRunIo, G904WithoutItsInputIsAnErrorAtItsLine) {
    ScratchDir scratch;
    const fs::path ini = tool_setter_ini(scratch.path(), -50);  // never reached
    const fs::path prog = scratch.path() / "miss.ngc";
    std::ofstream(prog) << "G90 G21\nG0 Z-5\n  G904 FZ-300 PZ3 LZ1 Z2\nG0 Z0\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    // why: 2 mm of maximum travel from Z-5 lands exactly on -7; the G904 is at column 3.
    const std::string error = prog.string() +
                              ":3:3: G904: Z stopped at -7 mm with input 3 not at level 1 (the "
                              "maximum travel or a soft limit came first)";
    EXPECT_NE(r.err.find(error), std::string::npos) << r.err;
    // The summary names it too: the interp component's error reaches motion, and motion's
    // `cnc run`, with its place apart from its cause (not "line 3: motion fault").
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), error) << r.out;
    const std::vector<double> pos = final_position(r.out);
    ASSERT_EQ(pos.size(), 3u) << r.out;
    EXPECT_NEAR(pos[2], -7, 1e-9);  // line 4 never ran
}

// M901 between two collinear moves switches the output without stopping the path.
TEST(CncRunIo, M901DoesNotStopThePath) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "out.ngc";
    std::ofstream(prog) << "G90 G21\nG1 X10 F600\nM901 H0 P1\nG1 X20\nM30\n";
    const fs::path csv = scratch.path() / "t.csv";
    const RunResult r = run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock --trace '{}'",
                                            prog.string(), csv.string()),
                                scratch.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream in(slurp(csv));
    std::string line;
    std::getline(in, line);  // t,line,x,y,z,j0,j1,j2,vel
    int near_x10 = 0;
    while (std::getline(in, line)) {
        std::vector<double> row;
        std::istringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
        if (row.size() != 9 || std::fabs(row[2] - 10) > 0.2) continue;
        ++near_x10;
        // why: F600 is 10 mm/s; a stop at X10 would show speeds down to 0 within 0.05 mm of it.
        EXPECT_NEAR(row[8], 10, 1e-6) << line;
    }
    EXPECT_GE(near_x10, 39);  // 0.4 mm at 10 mm/s: 40 periods
}

}  // namespace
