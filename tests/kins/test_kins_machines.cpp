// The sim machines whose motion component runs a kins_* module (kins=kins), end to end with
// `cnc run --sim-clock`: joints are motors, so a lagging drive shows its following error on
// its own joint, and a gantry's two Y motors are two joints.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cnc_run_harness.hpp"
#include "motion/kinematics.hpp"

namespace {

namespace fs = std::filesystem;
using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;
using cnc_test::slurp;

struct Edit {
    std::string section;  // "JOINT_1"; "JOINT_" for every joint
    std::string key, value;
};

// configs/sim/NAME.ini (paths absolute, see cnc_test::sim_ini) with the edits applied.
std::string ini_with(const std::string& name, const std::vector<Edit>& edits) {
    return cnc_test::sim_ini(name, [&](const std::string& section, std::string& line) {
        for (const Edit& e : edits) {
            const bool here =
                e.section.back() == '_' ? section.rfind(e.section, 0) == 0 : section == e.section;
            if (here && line.rfind(e.key + " = ", 0) == 0) line = e.key + " = " + e.value;
        }
    });
}

// "j0 0.0000  j1 2.4000 ..." of the summary -> {0.0, 2.4, ...}
std::vector<double> max_ferrors(const std::string& out) {
    return cnc_test::summary_axes(out, "max following error (mm)");
}

struct MachineRun {
    ScratchDir scratch;
    RunResult result;
    MachineRun(const std::string& ini_text, const std::string& program) {
        const fs::path ini = scratch.path() / "m.ini", ngc = scratch.path() / "p.ngc";
        std::ofstream(ini) << ini_text;
        std::ofstream(ngc) << program;
        result = run_cnc(fmt::format("'{}' '{}' --sim-clock --trace '{}'", ini.string(),
                                     ngc.string(), trace_path().string()),
                         scratch.path());
    }
    fs::path trace_path() const { return scratch.path() / "t.csv"; }
};

using cnc_test::csv_rows;

// A pure Y move on a CoreXY turns both motors, A = X + Y forward and B = X - Y backward, at
// the Y speed (50 mm/s here). motion is first in the servo thread, so its f-error compares this
// period's command with last period's feedback: a motor that follows exactly shows one period
// of travel, 50 mm/s x 1 ms = 0.05 mm (plus half an encoder count, 0.0005). Motor B's drive
// lags (first-order, 50 ms): it trails by up to speed x lag = 2.5 mm more, reached to within
// e^-18 during the 1 s cruise. Per-axis errors would have shown half of it on X and half on Y.
const char* kYMove = "G90 G21\nG01 Y50 F3000\nM30\n";
constexpr double kFollows = 0.05 + 0.0005 + 1e-6;
constexpr double kLagsMin = 2.4, kLagsMax = 2.5 + kFollows;

TEST(CoreXY, LaggingMotorShowsItsFollowingErrorOnItsOwnJoint) {
    MachineRun run(ini_with("corexy", {{"JOINT_1", "SIM_LAG", "0.05"}, {"JOINT_", "FERROR", "10"}}),
                   kYMove);
    ASSERT_EQ(run.result.exit_code, 0) << run.result.err << run.result.out;
    const std::vector<double> fe = max_ferrors(run.result.out);
    ASSERT_EQ(fe.size(), 3u) << run.result.out;
    EXPECT_LE(fe[0], kFollows);
    EXPECT_GT(fe[1], kLagsMin);
    EXPECT_LE(fe[1], kLagsMax);
    EXPECT_EQ(fe[2], 0.0);  // Z does not move
    EXPECT_NE(run.result.out.find("final position (mm): x 0.0000  y 50.0000  z 0.0000"),
              std::string::npos)
        << run.result.out;
}

TEST(CoreXY, LaggingMotorTripsItsOwnJoint) {
    // corexy.ini's FERROR of 1 mm on every joint: motor B passes it, motor A never comes near.
    MachineRun run(ini_with("corexy", {{"JOINT_1", "SIM_LAG", "0.05"}}), kYMove);
    EXPECT_EQ(run.result.exit_code, 1);
    EXPECT_NE(run.result.err.find(":2: following error on joint 1: "), std::string::npos)
        << run.result.err;
    EXPECT_EQ(run.result.err.find("on joint 0"), std::string::npos) << run.result.err;
}

// Gantry XYYZ: joints 1 and 2 are the two Y motors. One lags: its own joint shows it, the
// other Y motor follows exactly; both end at Y.
TEST(Gantry, TwoYMotorsAreTwoJoints) {
    MachineRun run(ini_with("gantry", {{"JOINT_2", "SIM_LAG", "0.05"}, {"JOINT_", "FERROR", "10"}}),
                   kYMove);
    ASSERT_EQ(run.result.exit_code, 0) << run.result.err << run.result.out;
    const std::vector<double> fe = max_ferrors(run.result.out);
    ASSERT_EQ(fe.size(), 4u) << run.result.out;
    EXPECT_EQ(fe[0], 0.0);  // X does not move
    EXPECT_LE(fe[1], kFollows);
    EXPECT_GT(fe[2], kLagsMin);
    EXPECT_LE(fe[2], kLagsMax);
    EXPECT_EQ(fe[3], 0.0);
}

// 5axis-trt.ini with a 40 mm tool under G43, the table tilting and turning while X moves. The
// trace has the axis commands (x y z a c: the nose, G43 having added 40 to z) and the motor
// feedback (j0..j4). At every sample the tool tip, 40 mm below the nose along machine Z, must
// be where the tables carry the programmed tip (x, y, z - 40) - using the config's pivots
// (Z_ROT_POINT = -80) without the tool. The ideal drives follow within the period the trace
// samples, to half an encoder count (0.0005 mm) per joint: 0.00087 mm in 3D (worst seen
// 0.00085). Without the tool length in the kinematics the tip would miss by 2 x 40 sin(A/2),
// 20.7 mm at A = 30.
TEST(FiveAxisTrt, ToolTipFollowsTheProgramUnderG43) {
    const char* program =
        "G90 G21\nG923 P1 Z40\nG43 H1\nG00 X10 Y5 Z-50\nG01 A30 C90 F600\nG01 X20 F1200\n"
        "G01 A0 C0 F600\nM30\n";
    MachineRun run(ini_with("5axis-trt", {}), program);
    ASSERT_EQ(run.result.exit_code, 0) << run.result.err << run.result.out;
    std::string header;
    const auto rows = csv_rows(slurp(run.trace_path()), header);
    ASSERT_EQ(header, "t,line,x,y,z,a,c,j0,j1,j2,j3,j4,vel");
    motion::TrtPivots plain;
    plain.a_pivot_mm = {0, 0, -80};
    plain.c_pivot_mm = {0, 0, 0};
    const motion::XyzacTrtKinematics table(plain);
    constexpr double kToolMm = 40;
    double max_a = 0, worst_mm = 0;
    std::size_t checked = 0;
    for (const auto& r : rows) {
        if (r[1] < 4) continue;  // before the first move under G43
        motion::AxisArray tip{};
        tip[0] = r[2];
        tip[1] = r[3];
        tip[2] = r[4] - kToolMm;
        tip[3] = r[5];
        tip[5] = r[6];
        std::vector<double> carried(5);
        table.inverse(tip, carried);
        const double dx = r[7] - carried[0], dy = r[8] - carried[1];
        const double dz = r[9] - kToolMm - carried[2];
        worst_mm = std::max(worst_mm, std::sqrt(dx * dx + dy * dy + dz * dz));
        max_a = std::max(max_a, r[5]);
        ++checked;
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_NEAR(max_a, 30.0, 1e-6);  // the run did tilt the table
    EXPECT_LT(worst_mm, 0.0005 * std::sqrt(3.0) + 1e-6) << "the tool tip left the programmed path";
}

// G49 (here M30's reset) with the table tilted would make the joints jump: refused as a
// program error naming the line, nothing jumps (no following-error trip).
TEST(FiveAxisTrt, ToolOffsetChangeWhileTiltedIsAProgramError) {
    const char* program = "G90 G21\nG923 P1 Z40\nG43 H1\nG00 X10 Y5 Z-50\nG01 A30 F600\nM30\n";
    MachineRun run(ini_with("5axis-trt", {}), program);
    EXPECT_EQ(run.result.exit_code, 1);
    // Joint 1 (machine Y) would jump by 40 sin 30 = 20 mm.
    EXPECT_NE(run.result.err.find(":6: the tool length offset changes to 0 mm while the "
                                  "kinematics use it: joint 1 would jump 20.0000 mm"),
              std::string::npos)
        << run.result.err;
    EXPECT_EQ(run.result.err.find("following error"), std::string::npos) << run.result.err;
}

}  // namespace
