// `cnc run` on configs/sim/mill.ini: every expected figure is derived from examples/pocket.ngc
// and the mill's INI by hand (see the comments), not copied from a run.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
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

using cnc_test::csv_rows;
using cnc_test::summary_axes;
using cnc_test::summary_field;
using cnc_test::summary_number;

const char* kPocketArgs = "configs/sim/mill.ini examples/pocket.ngc --sim-clock";

// The pocket with a trace (t.csv) and a preview (p.svg) written into `dir`.
std::string pocket_args_with_outputs(const fs::path& dir) {
    return fmt::format("{} --trace '{}' --preview '{}'", kPocketArgs, (dir / "t.csv").string(),
                       (dir / "p.svg").string());
}

// One run of the pocket with a trace, shared by the tests that only read its results.
class PocketRun : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        scratch_ = new ScratchDir;
        result_ =
            new RunResult(run_cnc(pocket_args_with_outputs(scratch_->path()), scratch_->path()));
        trace_ = new std::string(slurp(scratch_->path() / "t.csv"));
        svg_ = new std::string(slurp(scratch_->path() / "p.svg"));
    }
    static void TearDownTestSuite() {
        delete trace_;
        delete svg_;
        delete result_;
        delete scratch_;
    }
    static ScratchDir* scratch_;
    static RunResult* result_;
    static std::string* trace_;
    static std::string* svg_;
};
ScratchDir* PocketRun::scratch_ = nullptr;
RunResult* PocketRun::result_ = nullptr;
std::string* PocketRun::trace_ = nullptr;
std::string* PocketRun::svg_ = nullptr;

TEST_F(PocketRun, FinishesWithoutErrors) {
    EXPECT_EQ(result_->exit_code, 0) << result_->err;
    EXPECT_EQ(result_->err, "");
    EXPECT_NE(result_->out.find("\nresult: finished\n"), std::string::npos) << result_->out;
    EXPECT_NE(result_->out.find("\nerrors: none\n"), std::string::npos);
    EXPECT_NE(
        result_->out.find("program: examples/pocket.ngc (25 lines) on configs/sim/mill.ini\n"),
        std::string::npos);
}

TEST_F(PocketRun, EndsAtTheProgramsLastPoint) {
    // The program ends with G00 Z0 then G00 X10 Y5 (M30 moves nothing).
    EXPECT_NE(result_->out.find("\nfinal position (mm): x 10.0000  y 5.0000  z 0.0000\n"),
              std::string::npos)
        << result_->out;
}

TEST_F(PocketRun, PathLengthMatchesTheGeometry) {
    // Rapid (0,0)->(25,20): sqrt(25^2 + 20^2) = 32.0156; two passes of the outline: 2 x 30 +
    // 2 x 20 straight + four R5 quarter arcs (2 pi 5 = 31.4159) = 131.4159 each; plunges
    // 0.5 + 0.5, retract 1; rapid (25,20)->(10,5): 15 sqrt 2 = 21.2132. Total 318.0607.
    // Corner blends (tolerance 0.01 mm) only shorten it, by a few hundredths at most.
    const double length = summary_number(result_->out, "path length");
    EXPECT_LE(length, 318.0607 + 1e-3);
    EXPECT_GE(length, 318.0607 - 0.1);
}

TEST_F(PocketRun, MotionTimeIsBetweenTheBoundAndAReasonableMargin) {
    // Bound at the programmed feeds and the axis limits: 2 x 131.4159 mm at F1200 (20 mm/s) =
    // 13.1416 s, 1 mm of plunge at F300 = 0.2 s, rapid to (25,20) with X at 100 mm/s = 0.25 s,
    // 1 mm retract at Z's 50 mm/s = 0.02 s, diagonal 21.2132 mm with both axes at 100 mm/s =
    // 0.15 s: 13.76 s. Acceleration at the stops (90-degree plunge corners) adds a little.
    const double t = summary_number(result_->out, "motion time");
    EXPECT_GE(t, 13.76);
    EXPECT_LE(t, 13.76 * 1.25);
}

TEST_F(PocketRun, LimitsAreRespected) {
    // mill.ini: X and Y 100 mm/s, 1000 mm/s^2; Z 50 mm/s, 500 mm/s^2.
    const auto vel = summary_axes(result_->out, "max velocity (mm/s)");
    const auto acc = summary_axes(result_->out, "max acceleration (mm/s^2)");
    ASSERT_EQ(vel.size(), 3u) << result_->out;
    ASSERT_EQ(acc.size(), 3u);
    EXPECT_LE(vel[0], 100 + 1e-3);
    EXPECT_LE(vel[1], 100 + 1e-3);
    EXPECT_LE(vel[2], 50 + 1e-3);
    EXPECT_LE(acc[0], 1000 + 0.1);
    EXPECT_LE(acc[1], 1000 + 0.1);
    EXPECT_LE(acc[2], 500 + 0.1);
    EXPECT_GT(vel[0], 20);  // the rapids are faster than the feed
}

TEST_F(PocketRun, FollowingErrorIsOnePeriodOfTravel) {
    // Ideal followers with no lag: motion compares this period's command with the feedback of
    // the last one, so |f-error| <= speed x 1 ms + half an encoder count (1000 counts/mm):
    // X, Y <= 100 x 0.001 + 0.0005; Z <= 50 x 0.001 + 0.0005.
    const auto ferr = summary_axes(result_->out, "max following error (mm)");
    ASSERT_EQ(ferr.size(), 3u) << result_->out;
    EXPECT_LE(ferr[0], 0.1005 + 1e-9);
    EXPECT_LE(ferr[1], 0.1005 + 1e-9);
    EXPECT_LE(ferr[2], 0.0505 + 1e-9);
    EXPECT_GT(ferr[0], 0.0);
}

TEST_F(PocketRun, TraceHasOneRowPerServoCycleInsideTheProgramsExtents) {
    std::string header;
    const auto rows = csv_rows(*trace_, header);
    EXPECT_EQ(header, "t,line,x,y,z,j0,j1,j2,vel");
    ASSERT_FALSE(rows.empty());
    const double t = summary_number(result_->out, "motion time");
    EXPECT_EQ(static_cast<long>(rows.size()), std::lround(t / 0.001));
    for (std::size_t i = 0; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i].size(), 9u);
        EXPECT_NEAR(rows[i][0], 0.001 * static_cast<double>(i + 1), 1e-9);
        // The program stays within X 0..60, Y 0..50, Z -1..0 (cnc check's extents); blends
        // cut inside corners, never outside the hull.
        EXPECT_GE(rows[i][2], -1e-6);
        EXPECT_LE(rows[i][2], 60 + 1e-6);
        EXPECT_GE(rows[i][3], -1e-6);
        EXPECT_LE(rows[i][3], 50 + 1e-6);
        EXPECT_GE(rows[i][4], -1 - 1e-6);
        EXPECT_LE(rows[i][4], 1e-6);
        if (::testing::Test::HasFailure()) break;
    }
    const auto& last = rows.back();
    EXPECT_NEAR(last[2], 10, 1e-6);
    EXPECT_NEAR(last[3], 5, 1e-6);
    EXPECT_NEAR(last[4], 0, 1e-6);
    EXPECT_EQ(last[8], 0);  // at rest
}

TEST_F(PocketRun, PlainProgressLinesOncePerSecond) {
    // stdout is a file: one "progress:" line per whole second of motion time.
    const double t = summary_number(result_->out, "motion time");
    std::size_t lines = 0;
    for (std::size_t at = 0; (at = result_->out.find("progress: ", at)) != std::string::npos; ++at)
        ++lines;
    EXPECT_EQ(lines, static_cast<std::size_t>(std::floor(t)));
    EXPECT_EQ(result_->out.find('\r'), std::string::npos);
}

TEST_F(PocketRun, PreviewIsWritten) {
    // What the picture shows is checked in tests/cnc_preview (the PNG read back by panel).
    EXPECT_NE(svg_->find("<svg "), std::string::npos) << "not an SVG";
    EXPECT_NE(result_->out.find("\npreview: "), std::string::npos);
}

TEST_F(PocketRun, OutputIsByteIdenticalAcrossRuns) {
    ScratchDir scratch;
    const RunResult again = run_cnc(pocket_args_with_outputs(scratch.path()), scratch.path());
    EXPECT_EQ(again.exit_code, 0);
    // The last line names the preview file, which is in each run's own folder.
    const auto without_preview_line = [](const std::string& out) {
        return out.substr(0, out.rfind("preview: "));
    };
    EXPECT_EQ(without_preview_line(again.out), without_preview_line(result_->out));
    EXPECT_TRUE(slurp(scratch.path() / "t.csv") == *trace_) << "traces differ";
    EXPECT_TRUE(slurp(scratch.path() / "p.svg") == *svg_) << "previews differ";
}

TEST(CncRunErrors, BadProgramNamesFileAndLineAndMovesNothing) {
    ScratchDir scratch;
    const fs::path bad = scratch.path() / "bad.ngc";
    std::ofstream(bad) << "G90 G21\nG01 X10 F600\nG01 X20 Y#\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", bad.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err.rfind(bad.string() + ":3:", 0), 0u) << r.err;
    EXPECT_EQ(r.out.find("final position"), std::string::npos) << "nothing may run";
}

TEST(CncRunErrors, FeedMoveWithoutFeedIsRefusedBeforeMotion) {
    ScratchDir scratch;
    const fs::path bad = scratch.path() / "nofeed.ngc";
    std::ofstream(bad) << "G90 G21\nG01 X10\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", bad.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err.rfind(bad.string() + ":2:", 0), 0u) << r.err;
}

// The mill's INI says [AXIS_Z] MAX_LIMIT = 0; motion_xyz.hal wires it to axis.z.max-limit.
TEST(CncRunErrors, MoveBeyondTheIniSoftLimitIsRefused) {
    ScratchDir scratch;
    const fs::path high = scratch.path() / "high.ngc";
    std::ofstream(high) << "G90 G21\nG01 X10 F600\nG00 Z5\nM30\n";
    const RunResult r = run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", high.string()),
                                scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(
        r.err.find(high.string() + ":3:1: the move takes Z to 5 mm, which exceeds the soft limit "
                                   "axis.z.max-limit = 0 mm"),
        std::string::npos)
        << r.err;
}

// The program reaches motion through the interp component's stream, so the file name in a
// G906 timeout comes from the stream, not from a program= argument.
TEST(CncRunErrors, G906TimeoutNamesTheProgramFileAndLine) {
    ScratchDir scratch;
    const fs::path wait = scratch.path() / "wait.ngc";
    std::ofstream(wait) << "G90 G21\nG1 X10 F6000\nG906 PLC[0] LEVEL1 P500\nG1 X20\nM30\n";
    const RunResult r = run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", wait.string()),
                                scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(wait.string() +
                         ":3: G906: motion.digital-in-00 did not become TRUE within 0.5 s"),
              std::string::npos)
        << r.err;
}

// M00 pauses motion; with no terminal to press Enter on, the run must not hang.
TEST(CncRunPause, M00WithoutATerminalIsAnErrorAtItsLine) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "m00.ngc";
    std::ofstream(prog) << "G90 G21\nG1 X10 F600\nM00\nG1 X20\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock < /dev/null", prog.string()),
                scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(prog.string() + ":3: the program paused"), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("final position (mm): x 10.0000"), std::string::npos) << r.out;
}

TEST(CncRunPause, ResumePausesGoesOnAfterM00) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "m00.ngc";
    std::ofstream(prog) << "G90 G21\nG1 X10 F600\nM00\nG1 X20\nM30\n";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock --resume-pauses < /dev/null",
                            prog.string()),
                scratch.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find(prog.string() + ":3: program paused; resuming"), std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("final position (mm): x 20.0000"), std::string::npos) << r.out;
}

TEST(CncRunErrors, TimeoutStopsWithTheLineReached) {
    ScratchDir scratch;
    const RunResult r = run_cnc(fmt::format("{} --timeout 2", kPocketArgs), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    // After 2 s: 0.3 s of rapid and plunge, then 1.7 s at 20 mm/s along the 30 mm line 6.
    EXPECT_NE(r.err.find("examples/pocket.ngc:6: not finished after 2 s of motion"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos);
}

TEST(CncRunErrors, IniWithoutHalFileIsAConfigError) {
    ScratchDir scratch;
    const fs::path ini = scratch.path() / "empty.ini";
    std::ofstream(ini) << "[EMCMOT]\nSERVO_PERIOD = 1000000\n";
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("[HAL]HALFILE is missing"), std::string::npos) << r.err;
}

}  // namespace

namespace {

// The other sim configs run the same pocket; their axes end where the program ends.
class OtherConfigs : public ::testing::TestWithParam<const char*> {};

TEST_P(OtherConfigs, PocketFinishesAtTheProgramsLastPoint) {
    ScratchDir scratch;
    const RunResult r =
        run_cnc(fmt::format("configs/sim/{}.ini examples/pocket.ngc --sim-clock", GetParam()),
                scratch.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 10.0000  y 5.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
    // Same geometry as on the mill (PocketRun.PathLengthMatchesTheGeometry).
    const double length = summary_number(r.out, "path length");
    EXPECT_LE(length, 318.0607 + 1e-3);
    EXPECT_GE(length, 318.0607 - 0.1);
}

INSTANTIATE_TEST_SUITE_P(Sim, OtherConfigs, ::testing::Values("mill-servo", "gantry", "corexy"),
                         [](const auto& info) {
                             std::string n = info.param;
                             for (char& c : n)
                                 if (c == '-') c = '_';
                             return n;
                         });

TEST(FiveAxis, RotaryMovesEndAtTheProgrammedAngles) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "five.ngc";
    std::ofstream(prog) << "G90 G21\nG00 X10 Y5 Z-10\nG01 A30 F600\nG01 C90\nG01 X20 F1200\nM30\n";
    const fs::path csv = scratch.path() / "t.csv";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/5axis-trt.ini '{}' --sim-clock --trace '{}'",
                            prog.string(), csv.string()),
                scratch.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find(
                  "\nfinal position (mm): x 20.0000  y 5.0000  z -10.0000  a 30.0000  c 90.0000\n"),
              std::string::npos)
        << r.out;
    // Path length counts the linear axes only. NcStudio's G00 moving down goes XY first, then
    // Z: |(10,5)| = 11.1803, then 10 down, then the 10 mm X move: 31.1803, less a blend.
    const double length = summary_number(r.out, "path length");
    EXPECT_LE(length, 31.1803 + 1e-3);
    EXPECT_GE(length, 31.1803 - 0.05);
    std::string header;
    csv_rows(slurp(csv), header);
    EXPECT_EQ(header, "t,line,x,y,z,a,c,j0,j1,j2,j3,j4,vel");
}

}  // namespace

namespace {

// mill.ini with the HAL files by absolute path and `key` set to `value` in `section` (every
// section when empty).
std::string mill_ini_with(const std::string& section, const std::string& key,
                          const std::string& value) {
    return cnc_test::sim_ini("mill", [&](const std::string& current, std::string& line) {
        if (line.rfind(key + " = ", 0) == 0 && (section.empty() || section == current))
            line = key + " = " + value;
    });
}

TEST(CncRunErrors, FollowingErrorTripNamesLineAndJoint) {
    ScratchDir scratch;
    const fs::path ini = scratch.path() / "tight.ini";
    std::ofstream(ini) << mill_ini_with("", "FERROR", "0.05");
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    // f-error is about one period of travel: it passes 0.05 mm when X, the faster axis of the
    // first rapid (line 4, X25 Y20), passes 50 mm/s on its way to 100 mm/s. One period later it
    // is at most 1000 mm/s^2 x 1 ms x 1 ms + half a count (0.0005) beyond.
    const std::string prefix = "examples/pocket.ngc:4: following error on joint 0: ";
    ASSERT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
    const double ferror_mm = std::stod(r.err.substr(prefix.size()));
    EXPECT_GT(ferror_mm, 0.05);
    EXPECT_LE(ferror_mm, 0.05 + 0.001 + 0.0005);
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos);
}

}  // namespace

namespace {

TEST(CncRunFolders, RunsFromAnyWorkingFolder) {
    // The sim INIs' HALLIB is found beside the sourcing HAL file, not in the working folder.
    ScratchDir scratch;
    const fs::path root = CNC_SOURCE_DIR;
    const RunResult r =
        run_cnc(fmt::format("'{}' '{}' --sim-clock", (root / "configs/sim/mill.ini").string(),
                            (root / "examples/pocket.ngc").string()),
                scratch.path(), scratch.path());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 10.0000  y 5.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

}  // namespace

namespace {

TEST(CncRunStop, SigtermAbortsWithAControlledStop) {
    // Real time: the pocket takes about 15 s; SIGTERM (as Ctrl-C) after 1 s aborts it. The shell
    // runs cnc in the background, where SIGINT would be ignored, hence SIGTERM.
    ScratchDir scratch;
    const fs::path out = scratch.path() / "stdout.txt", err = scratch.path() / "stderr.txt";
    const std::string cmd = fmt::format(
        "cd '{}' && {{ '{}' run configs/sim/mill.ini examples/pocket.ngc > '{}' 2> '{}' & "
        "pid=$!; sleep 1; kill -TERM $pid; wait $pid; }}",
        CNC_SOURCE_DIR, CNC_BIN, out.string(), err.string());
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    const std::string o = slurp(out), e = slurp(err);
    EXPECT_NE(e.find("stopped on request (Ctrl-C or SIGTERM)"), std::string::npos) << e;
    EXPECT_NE(o.find("\nresult: stopped on request\n"), std::string::npos) << o;
    // Stopped along the path, inside the program's extents (X 0..60, Y 0..50, Z -1..0), not
    // at its end (X10 Y5 after about 15 s).
    const auto pos = summary_axes(o, "final position (mm)");
    ASSERT_EQ(pos.size(), 3u) << o;
    EXPECT_GE(pos[0], 0);
    EXPECT_LE(pos[0], 60);
    EXPECT_GE(pos[1], 0);
    EXPECT_LE(pos[1], 50);
    EXPECT_LT(summary_number(o, "motion time"), 10.0);
}

}  // namespace

namespace {

TEST(CncRunRealTime, TraceAndSummaryEqualTheSimulatedClocks) {
    // In real time a sampler stream records every servo cycle. The program fits in motion's
    // queue, so it is fully planned before the first cycle, and a late cycle is skipped, not
    // replayed: the commanded path per cycle is the same as under --sim-clock.
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "square.ngc";
    std::ofstream(prog) << "G90 G21\nG01 X10 F600\nG01 Y10\nM30\n";
    std::string outs[2], traces[2];
    for (int i = 0; i < 2; ++i) {
        const fs::path csv = scratch.path() / fmt::format("t{}.csv", i);
        const RunResult r =
            run_cnc(fmt::format("configs/sim/mill.ini '{}' --trace '{}' {}", prog.string(),
                                csv.string(), i == 0 ? "--sim-clock" : ""),
                    scratch.path());
        ASSERT_EQ(r.exit_code, 0) << r.err;
        outs[i] = r.out;
        traces[i] = slurp(csv);
    }
    EXPECT_TRUE(traces[0] == traces[1]) << "traces differ";
    const auto pos = outs[0].find("clock: simulated");
    ASSERT_NE(pos, std::string::npos);
    EXPECT_EQ(outs[0].replace(pos, 16, "clock: real time"), outs[1]);
    // 10 mm + 10 mm at F600 (10 mm/s) with a stop at the corner: a little over 2 s.
    const double t = summary_number(outs[1], "motion time");
    EXPECT_GT(t, 2.0);
    EXPECT_LT(t, 2.5);
}

TEST(CncRunErrors, DriveOverSpeedTripsTheEStop) {
    // X's simulated drive trips above 50 mm/s (SIM_MAX_VEL): X passes that on the first rapid
    // (line 4, X25 Y20, on its way to 100 mm/s); the drive fault trips the e-stop latch, which
    // disables motion.
    ScratchDir scratch;
    const fs::path ini = scratch.path() / "slow.ini";
    std::ofstream(ini) << mill_ini_with("JOINT_0", "SIM_MAX_VEL", "50");
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err,
              "examples/pocket.ngc:4: the machine was disabled during the program (e-stop: "
              "motion.enable went FALSE); drive fault on joint 0 (amp-fault-in)\n");
    // Stopped at once, not at the end of the rapid (25, 20): at about 50 mm/s X has moved
    // v^2 / 2a = 50^2 / 2000 = 1.25 mm plus what the jerk limit adds, Y 4/5 of that.
    const auto pos = summary_axes(r.out, "final position (mm)");
    ASSERT_EQ(pos.size(), 3u) << r.out;
    EXPECT_GT(pos[0], 1.0);
    EXPECT_LT(pos[0], 3.0);
    EXPECT_NEAR(pos[1], pos[0] * 20 / 25, 1e-3);
}

TEST(CncRunErrors, LatePlannerErrorRunsOutThePlannedMovesThenFails) {
    // 10 000 short moves (more than motion's 4096-record queue), then a bad line: the error is
    // found while the machine already runs. The moves before it still run out; the last good
    // line (i = 9999) is X (9999 % 100) * 0.5 = 49.5, Y (9999 / 200) * 0.5 = 24.5.
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "late.ngc";
    {
        std::ofstream out(prog);
        out << "G90 G21\nG01 F6000\n";
        for (int i = 0; i < 10000; ++i)
            out << fmt::format("G01 X{:.3f} Y{:.3f}\n", (i % 100) * 0.5, (i / 200) * 0.5);
        out << "G01 X10 Y#\nM30\n";
    }
    const RunResult r = run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", prog.string()),
                                scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    // The bad line is 2 + 10000 + 1 = 10003; '#' is its 10th column.
    EXPECT_NE(r.err.find(prog.string() + ":10003:10: "), std::string::npos) << r.err;
    // The summary names the bad line too, not the line running when it was found.
    EXPECT_EQ(summary_field(r.out, "errors").rfind(prog.string() + ":10003:10: ", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 49.5000  y 24.5000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

TEST(CncRunErrors, HalFileErrorNamesFileAndLine) {
    ScratchDir scratch;
    std::ofstream(scratch.path() / "bad.hal")
        << "loadrt threads name1=servo-thread period1=1000000\nnet x-pos-cmd nosuch.pin\n";
    std::ofstream(scratch.path() / "bad.ini")
        << "[EMCMOT]\nSERVO_PERIOD = 1000000\n[HAL]\nHALFILE = bad.hal\n";
    const RunResult r = run_cnc(
        fmt::format("'{}' examples/pocket.ngc --sim-clock", (scratch.path() / "bad.ini").string()),
        scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    // HALFILE is relative to the INI's folder; the error is on its line 2.
    EXPECT_EQ(r.err.rfind((scratch.path() / "bad.hal").string() + ":2: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("nosuch.pin"), std::string::npos) << r.err;
}

TEST(CncRunErrors, ConfigWithoutMotionIsRefused) {
    ScratchDir scratch;
    std::ofstream(scratch.path() / "bare.hal")
        << "loadrt threads name1=servo-thread period1=1000000\n";
    const fs::path ini = scratch.path() / "bare.ini";
    std::ofstream(ini) << "[EMCMOT]\nSERVO_PERIOD = 1000000\n[HAL]\nHALFILE = bare.hal\n";
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err, ini.string() +
                         ": the HAL files do not load the motion component (no pin "
                         "motion.in-position)\n");
}

}  // namespace

namespace {

// The sim configs run the program through the interp component and its stream. A read of the
// machine's position (#CURMACHPOS.X) and G906 make the interpreter wait for motion: the
// machine stops there in position, which is not yet the end of the program.
TEST(CncRunInterp, QueueBustingReadsWaitForTheMachineAndRunTheSameEveryTime) {
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "read.ngc";
    std::ofstream(prog) << "G90 G21\nG01 X10 F600\n#1 = #CURMACHPOS.X\nG01 Y=#1\nG906\n"
                           "G01 X0 Y0\nM30\n";
    std::string outs[2], traces[2];
    for (int i = 0; i < 2; ++i) {
        const fs::path csv = scratch.path() / fmt::format("t{}.csv", i);
        const RunResult r =
            run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock --trace '{}'", prog.string(),
                                csv.string()),
                    scratch.path());
        ASSERT_EQ(r.exit_code, 0) << r.err;
        outs[i] = r.out;
        traces[i] = slurp(csv);
    }
    EXPECT_EQ(outs[0], outs[1]);
    EXPECT_TRUE(traces[0] == traces[1]) << "traces differ";
    // Not ended at the stop where the read waits (X10 Y0): the last move returns to X0 Y0.
    EXPECT_NE(outs[0].find("\nfinal position (mm): x 0.0000  y 0.0000  z 0.0000\n"),
              std::string::npos)
        << outs[0];
    // The Y move of line 4 goes to the X position read on line 3: the path reaches Y10 and
    // stands still there (G906) before the diagonal home.
    std::string header;
    const auto rows = csv_rows(traces[0], header);
    double max_y = 0;
    for (const auto& row : rows) max_y = std::max(max_y, row[3]);
    EXPECT_NEAR(max_y, 10.0, 1e-9);
    // 10 + 10 + 14.14 mm at 10 mm/s with stops between: a little over 3.4 s.
    const double t = summary_number(outs[0], "motion time");
    EXPECT_GT(t, 3.41);
    EXPECT_LT(t, 4.0);
}

TEST(CncRunInterp, InterpreterErrorAfterAReadStopsTheMachineAndNamesFileLineCol) {
    // The error on line 4 is found only after the read on line 3 has waited for the X move:
    // the machine ends at X10, the run fails with the interpreter's file:line:col ('Q' is
    // column 9 of "G01 X20 Q").
    ScratchDir scratch;
    const fs::path prog = scratch.path() / "late.ngc";
    std::ofstream(prog) << "G90 G21\nG01 X10 F600\n#1 = #CURMACHPOS.X\nG01 X20 Q\nM30\n";
    const RunResult r = run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", prog.string()),
                                scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(prog.string() + ":4:9: expected a number or '=' after Q"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("\nresult: error\n"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\nfinal position (mm): x 10.0000  y 0.0000  z 0.0000\n"),
              std::string::npos)
        << r.out;
}

TEST(CncRunInterp, SyntaxErrorNamesColumnAndNothingMoves) {
    ScratchDir scratch;
    const fs::path bad = scratch.path() / "bad.ngc";
    std::ofstream(bad) << "G90 G21\nG01 X10 F600\nG01 X20 Q\nM30\n";  // 'Q': column 9
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock", bad.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.err, bad.string() + ":3:9: expected a number or '=' after Q\n");
    EXPECT_EQ(r.out.find("final position"), std::string::npos) << "nothing may run";
}

}  // namespace
