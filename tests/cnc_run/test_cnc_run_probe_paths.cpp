// The same G904 program on the sim mill's two program paths: the interp component (the
// interpreter in its own thread, queue-busting reads wait for motion and read
// interp.machine-pos-L) and motion's own program= (the interpreter inside motion's feeder).
// Both must agree on what a program sees after a conditional move: #CURMACHPOS / #CURWORKPOS
// are where the machine stands (the stop point, a braking distance past the switch: S0 §4.1.2
// names them the machine coordinates of the current point, and G919 exists to measure how far
// past the trigger an axis stopped), while the interpreter's own position, from which the
// next incremental move is measured, is the trip point (S0 §3.5.3's tool-setting routine
// takes the touch height as the lift's end minus the lift).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <ostream>
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

// halfiles/motion_xyz.hal with motion running the program itself (program=, the same INI and
// settings folder the interp component would get) and everything that talks to the interp
// component left out; the machine's inputs go to motion alone.
std::string feeder_motion_xyz() {
    std::istringstream in(slurp(fs::path(CNC_SOURCE_DIR) / "halfiles/motion_xyz.hal"));
    std::string text, line;
    while (std::getline(in, line)) {
        if (line == "source interp.hal") continue;
        if (line == "source interp-io.hal") {
            for (int n = 0; n < 4; ++n)
                text += fmt::format("net dio-in-0{0} => motion.digital-in-0{0}\n", n);
            continue;
        }
        const std::string canon = "canon=interp.canon";
        if (const auto at = line.find(canon); at != std::string::npos)
            line.replace(at, canon.size(),
                         "program=\"$(CNC_PROGRAM)\" ini=\"$(INI_FILE_NAME)\" "
                         "settings_dir=\"$(CNC_SETTINGS_DIR)\"");
        else if (line.find("interp.") != std::string::npos)
            continue;
        text += line + "\n";
    }
    return text;
}

enum class Path { InterpComponent, MotionProgram };

const char* path_name(Path p) {
    return p == Path::InterpComponent ? "InterpComponent" : "MotionProgram";
}
void PrintTo(Path p, std::ostream* os) {
    *os << path_name(p);
}

// configs/sim/mill.ini plus the setter; on the motion path its mill-motion.hal sources the
// edited motion_xyz.hal instead of the stock one.
fs::path setter_ini(const fs::path& dir, Path path) {
    const fs::path setter = cnc_test::tool_setter_hal(dir, -12.5);
    fs::path motion_hal;
    if (path == Path::MotionProgram) {
        motion_hal = dir / "feeder-motion.hal";
        std::istringstream in(slurp(fs::path(CNC_SOURCE_DIR) / "configs/sim/mill-motion.hal"));
        std::string text, line;
        while (std::getline(in, line))
            text += line == "source [HAL]HALLIB/motion_xyz.hal" ? feeder_motion_xyz() : line + "\n";
        EXPECT_NE(text.find("program=\"$(CNC_PROGRAM)\""), std::string::npos) << text;
        std::ofstream(motion_hal) << text;
    }
    const fs::path ini = dir / "setter.ini";
    std::ofstream(ini) << cnc_test::sim_ini("mill", [&](const std::string&, std::string& line) {
        if (line.rfind("HALFILE = ", 0) != 0) return;
        if (!motion_hal.empty() && line.find("mill-motion.hal") != std::string::npos)
            line = "HALFILE = " + motion_hal.string();
        if (line.find("io-loopback.hal") != std::string::npos)
            line += "\nHALFILE = " + setter.string();
    });
    return ini;
}

RunResult run_on(Path path, const ScratchDir& scratch, const std::string& program) {
    const fs::path ini = setter_ini(scratch.path(), path);
    const fs::path prog = scratch.path() / "probe.ngc";
    std::ofstream(prog) << program;
    return run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()),
                   scratch.path());
}

// The G904 touches the setter; lines 5-6 read where the machine stands, line 9 reads again
// after an incremental lift, and the last moves write the three readings into the final
// position, where the summary shows them.
const char* const kProgram =
    "G90 G21\n"
    "G0 X10 Y10\n"
    "G0 Z-5\n"
    "G904 FZ-300 PZ3 LZ1 Z50\n"
    "#1 = #CURMACHPOS.Z\n"
    "#2 = #CURWORKPOS.Z\n"
    "G91 G0 Z5\n"
    "G90\n"
    "#3 = #CURMACHPOS.Z\n"
    "G0 X=20+#1 Y=20+#2\n"
    "G0 Z=#3-1\n"
    "M30\n";

class ProbePaths : public ::testing::TestWithParam<Path> {};

TEST_P(ProbePaths, CurMachPosAfterG904IsTheStopAndTheLiftStartsAtTheTrip) {
    ScratchDir scratch;
    const RunResult r = run_on(GetParam(), scratch, kProgram);
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    const std::vector<double> pos = cnc_test::summary_axes(r.out, "final position (mm)");
    ASSERT_EQ(pos.size(), 3u) << r.out;
    // why: Z (500 mm/s^2) ramps from Z-5 to 5 mm/s in 10 periods of 1 ms (0.025 mm), then moves
    // 5 um a period: Z = -5.025 - 0.005 k, -12.5 at k = 1495, where the setter's comparator
    // (in1 > in0) is still FALSE; it closes at -12.505. Motion sees the input in the next period
    // and keeps the command of the period before as the trip point, -12.505, then brakes from
    // 5 mm/s: 10 periods of 4.75, 4.25 ... 0.25 um = 0.025 mm, so Z stops at -12.530.
    // #1 = #2 = -12.530 (no work offsets): X = Y = 20 - 12.530 = 7.470.
    EXPECT_NEAR(pos[0], 7.470, 1e-4) << "#CURMACHPOS.Z after the G904 was " << pos[0] - 20;
    EXPECT_NEAR(pos[1], 7.470, 1e-4) << "#CURWORKPOS.Z after the G904 was " << pos[1] - 20;
    // why: the G91 Z5 is measured from the trip point: -12.505 + 5 = -7.505, where the machine
    // then stands, so #3 = -7.505 and the last move goes to -8.505.
    EXPECT_NEAR(pos[2], -8.505, 1e-4) << "#CURMACHPOS.Z after the lift was " << pos[2] + 1;
}

INSTANTIATE_TEST_SUITE_P(CncRunProbe, ProbePaths,
                         ::testing::Values(Path::InterpComponent, Path::MotionProgram),
                         [](const ::testing::TestParamInfo<Path>& info) {
                             return std::string(path_name(info.param));
                         });

}  // namespace
