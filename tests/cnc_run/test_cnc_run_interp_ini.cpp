// `cnc run` with the interpreter options of the INI's [RS274NGC] section: the "use default
// speed" switch (FEATURES G00-4) reaches the interp component, so a program's F words give way
// to the machine's default feed except in G905 blocks; a bad value is reported as the INI's
// file:line before anything is loaded. Speeds are read from the trace, by hand from the
// program: F3000 = 50 mm/s, F1200 = 20 mm/s, the INI's default 600 mm/min = 10 mm/s.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
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

// configs/sim/mill.ini with its HAL files named by absolute path and `rs274ngc` (lines) added
// at the top of its [RS274NGC] section.
fs::path mill_ini_with(const fs::path& dir, const std::string& rs274ngc) {
    const std::string lines = rs274ngc.substr(0, rs274ngc.find_last_not_of('\n') + 1);
    const fs::path ini = dir / "machine.ini";
    std::ofstream(ini) << cnc_test::sim_ini("mill", [&](const std::string&, std::string& line) {
        if (line == "[RS274NGC]" && !lines.empty()) line += "\n" + lines;
    });
    return ini;
}

// The highest path speed (trace column vel) seen while motion.program-line was each line.
std::map<int, double> top_speed_by_line(const std::string& csv) {
    std::string header;
    std::map<int, double> top;
    for (const auto& row : cnc_test::csv_rows(csv, header)) {
        if (row.size() < 9) continue;  // t,line,x,y,z,j0,j1,j2,vel
        double& v = top[static_cast<int>(row[1])];
        v = std::max(v, row[8]);
    }
    return top;
}

struct FeedRun {
    RunResult result;
    std::map<int, double> top_mm_s;
};

FeedRun run_feeds(const ScratchDir& scratch, const std::string& rs274ngc) {
    const fs::path ini = mill_ini_with(scratch.path(), rs274ngc);
    const fs::path prog = scratch.path() / "feeds.ngc";
    std::ofstream(prog) << "G90 G21\nG1 X20 F3000\nG905 G1 X30 F1200\nM30\n";
    const fs::path csv = scratch.path() / "t.csv";
    FeedRun run;
    run.result = run_cnc(fmt::format("'{}' '{}' --sim-clock --trace '{}'", ini.string(),
                                     prog.string(), csv.string()),
                         scratch.path());
    run.top_mm_s = top_speed_by_line(slurp(csv));
    return run;
}

TEST(CncRunInterpIni, WithoutTheSwitchTheProgrammedFeedsRun) {
    ScratchDir scratch;
    const FeedRun r = run_feeds(scratch, "");
    ASSERT_EQ(r.result.exit_code, 0) << r.result.err << r.result.out;
    // why: 20 mm at F3000 = 50 mm/s (inside X's 100 mm/s) reaches its speed after 2.5 mm of
    // S-curve (t = 2 sqrt(50/20000) = 0.1 s at average 25 mm/s); line 3 runs at its F1200.
    EXPECT_NEAR(r.top_mm_s.at(2), 50, 1e-6);
    EXPECT_NEAR(r.top_mm_s.at(3), 20, 1e-6);
    // why: at least 20/50 + 10/20 = 0.9 s of cruising.
    const double t_s = cnc_test::summary_number(r.result.out, "motion time");
    EXPECT_GT(t_s, 0.9);
    EXPECT_LT(t_s, 1.1);
}

TEST(CncRunInterpIni, UseDefaultSpeedRunsTheDefaultFeedExceptInG905Blocks) {
    ScratchDir scratch;
    const FeedRun r = run_feeds(scratch, "USE_DEFAULT_SPEED = 1\nDEFAULT_FEED_MM_MIN = 600\n");
    ASSERT_EQ(r.result.exit_code, 0) << r.result.err << r.result.out;
    // why: line 2's F3000 gives way to the default 600 mm/min = 10 mm/s; the G905 block of
    // line 3 runs at its own F1200 = 20 mm/s.
    EXPECT_NEAR(r.top_mm_s.at(2), 10, 1e-6);
    EXPECT_NEAR(r.top_mm_s.at(3), 20, 1e-6);
    // why: at least 20/10 + 10/20 = 2.5 s of cruising; the S-curve ramps (0->10, 10->20,
    // 20->0 mm/s at 20000 mm/s^3 take 0.045, 0.045 and 0.063 s) add well under 0.1 s.
    const double t_s = cnc_test::summary_number(r.result.out, "motion time");
    EXPECT_GT(t_s, 2.5);
    EXPECT_LT(t_s, 2.6);
    const std::vector<double> pos = cnc_test::summary_axes(r.result.out, "final position (mm)");
    ASSERT_EQ(pos.size(), 3u);
    EXPECT_NEAR(pos[0], 30, 1e-9);
}

TEST(CncRunInterpIni, ABadValueIsReportedAtItsIniLineBeforeAnythingLoads) {
    ScratchDir scratch;
    const fs::path ini = mill_ini_with(scratch.path(), "USE_DEFAULT_SPEED = sometimes\n");
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 2);
    // why: the key is the first line after [RS274NGC], which is line 16 of mill.ini.
    EXPECT_EQ(r.err,
              ini.string() + ":17: [RS274NGC]USE_DEFAULT_SPEED = sometimes: expected 0 or 1\n");
    EXPECT_EQ(r.out, "");
}

TEST(CncRunInterpIni, TheSwitchWithoutADefaultFeedIsRefused) {
    ScratchDir scratch;
    const fs::path ini = mill_ini_with(scratch.path(), "USE_DEFAULT_SPEED = 1\n");
    const RunResult r =
        run_cnc(fmt::format("'{}' examples/pocket.ngc --sim-clock", ini.string()), scratch.path());
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err,
              ini.string() +
                  ":17: [RS274NGC]USE_DEFAULT_SPEED = 1: needs "
                  "[RS274NGC]DEFAULT_FEED_MM_MIN > 0, the speed every feed move then runs at\n");
}

}  // namespace
