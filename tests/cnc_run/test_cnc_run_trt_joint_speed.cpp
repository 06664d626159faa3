// `cnc run` on configs/sim/5axis-trt.ini with the soak's reproducer of a motor over-speed: the
// table tilted to A = -65 with a workpiece point about 42 mm off the C axis, then a rapid in C,
// a rapid in workpiece Y, and a fed C/A move. The planner limits the axes only; under this
// kinematics the motion component caps each move's speed so that every motor stays within
// [JOINT_N]MAX_VELOCITY (components/motion/joint_limits.hpp, "Joint rates at plan time").
// Before that, the G0 A-65 commanded joint 2 (machine Z, MAX_VELOCITY 50) 100 mm/s and its
// simulated drive tripped at SIM_MAX_VEL 100: a drive fault and an e-stop.
//
// Geometry, by hand: the A axis runs parallel to X through Y = 0, Z = -80; (30, 29.4, -20) lies
// 42.0 mm off the C axis and 66.8 mm off the A axis. At A = -65 a workpiece Y move drives
// machine Z at sin 65 = 0.906 mm/mm, and a C turn moves the point 0.733 mm/deg.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "cnc_run_harness.hpp"

namespace {

namespace fs = std::filesystem;

// [JOINT_0..4] MAX_VELOCITY of configs/sim/5axis-trt.ini.
constexpr std::array<double, 5> kJointMaxVel = {100, 100, 50, 90, 180};

constexpr const char* kReproducer =
    "G90 G21\n"
    "G0 X30 Y29.4 Z-20\n"
    "G0 A-65\n"
    "G0 C-71.48\n"
    "G0 Y-29.4\n"
    "G1 C20 A-30 F3000\n"
    "G0 A0 C0\n"
    "M30\n";

// Velocities over 20 periods: the trace gives joints to 0.001 mm, so a one-period difference
// is off by up to 1 mm/s; over 20 periods by 0.05 mm/s at most.
constexpr std::size_t kWindow = 20;
constexpr double kRoundingMmS = 0.001 / (kWindow * 0.001);

struct Peaks {
    std::array<double, 5> all{}, tilted{};  // tilted: over lines 3 to 7
};

// Runs the reproducer on 5axis-trt.ini (plus `extra_hal`, if given) and checks that it
// finishes without a drive fault or a velocity report, every move line having run; returns
// the joints' peak velocities from the trace.
Peaks run_reproducer(const cnc_test::ScratchDir& scratch, const std::string& extra_hal = "") {
    const fs::path prog = scratch.path() / "tilted.ngc";
    std::ofstream(prog) << kReproducer;
    std::string ini = "configs/sim/5axis-trt.ini";
    if (!extra_hal.empty()) {
        const fs::path hal = scratch.path() / "extra.hal";
        std::ofstream(hal) << extra_hal;
        ini = (scratch.path() / "machine.ini").string();
        std::ofstream(ini) << cnc_test::sim_ini(
            "5axis-trt", [&](const std::string& section, std::string& line) {
                if (section == "HAL" && line.find("io-loopback.hal") != std::string::npos)
                    line += "\nHALFILE = " + hal.string();
            });
    }
    const fs::path trace = scratch.path() / "trace.csv";
    const cnc_test::RunResult r = cnc_test::run_cnc(
        fmt::format("'{}' '{}' --sim-clock --trace '{}'", ini, prog.string(), trace.string()),
        scratch.path());
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_EQ(cnc_test::summary_field(r.out, "errors"), "none") << r.out;
    EXPECT_EQ(r.err.find("drive fault"), std::string::npos) << r.err;
    // The servo function's report-only check has nothing to say about velocity.
    EXPECT_EQ(r.err.find("commanded a velocity"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 30.0000  y -29.4000  z -20.0000  a 0.0000  "
                         "c 0.0000\n"),
              std::string::npos)
        << r.out;

    Peaks peaks;
    std::string header;
    const auto rows = cnc_test::csv_rows(cnc_test::slurp(trace), header);
    EXPECT_EQ(header, "t,line,x,y,z,a,c,j0,j1,j2,j3,j4,vel");
    if (header != "t,line,x,y,z,a,c,j0,j1,j2,j3,j4,vel" || rows.size() < 1000) {
        ADD_FAILURE() << "trace has " << rows.size() << " rows";
        return peaks;
    }
    std::array<bool, 8> lines_seen{};
    for (std::size_t i = kWindow; i < rows.size(); ++i) {
        const double dt = rows[i][0] - rows[i - kWindow][0];
        for (std::size_t j = 0; j < peaks.all.size(); ++j) {
            const double v = std::fabs(rows[i][7 + j] - rows[i - kWindow][7 + j]) / dt;
            peaks.all[j] = std::max(peaks.all[j], v);
            if (rows[i - kWindow][1] >= 3) peaks.tilted[j] = std::max(peaks.tilted[j], v);
        }
        const auto line = static_cast<std::size_t>(rows[i][1]);
        if (line < lines_seen.size()) lines_seen[line] = true;
    }
    for (std::size_t line = 2; line <= 7; ++line) EXPECT_TRUE(lines_seen[line]) << line;
    for (std::size_t j = 0; j < peaks.all.size(); ++j)
        EXPECT_LE(peaks.all[j], kJointMaxVel[j] * (1 + 1e-3) + kRoundingMmS) << "joint " << j;
    return peaks;
}

TEST(CncRunTrtJointSpeed, TiltedTableReproducerKeepsEveryMotorWithinItsMaxVelocity) {
    cnc_test::ScratchDir scratch;
    const Peaks p = run_reproducer(scratch);
    // On the tilted moves the motors that bind (Z on the A turn, Y on the last rapid) run at
    // their limit over the highest override, 1.2 (kept for an override of 120 %), not slower.
    EXPECT_LE(p.tilted[2], 50 / 1.2 + kRoundingMmS);
    EXPECT_GE(p.tilted[2], 50 / 1.2 * 0.99);
    EXPECT_LE(p.tilted[1], 100 / 1.2 + kRoundingMmS);
    EXPECT_GE(p.tilted[1], 100 / 1.2 * 0.99);
}

TEST(CncRunTrtJointSpeed, At120PercentOverrideTheMotorsReachButDoNotPassTheirLimits) {
    cnc_test::ScratchDir scratch;
    const Peaks p =
        run_reproducer(scratch, "setp motion.feed-override 1.2\nsetp motion.rapid-override 1.2\n");
    // The caps leave exactly the override's room: the binding motors now run at their limits.
    EXPECT_GE(p.tilted[2], 50 * 0.99);
    EXPECT_GE(p.tilted[1], 100 * 0.99);
}

}  // namespace
