// `cnc run` keeps the interpreter's state between runs, as LinuxCNC does: work offsets, G92 and
// persistent parameters in [RS274NGC]PARAMETER_FILE, tool lengths in [EMCIO]TOOL_TABLE. Each
// test keeps them in its own scratch folder (--settings-dir), so tests run in parallel and
// never write into configs/sim. Positions are checked by hand from configs/sim/mill.ini
// (X 0..400, Y 0..300, Z -100..0), configs/sim/mill.tbl (T1 Z40, T2 Z35) and the programs.
// NcStudio writes work offsets with G922 P<n> (P0 = G54) and tool lengths with G923; ISO's
// G10 L2 is not implemented by the interpreter. A hand-written tool table keeps its lines and
// words; a second run on the same files at once is refused.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cnc_run_harness.hpp"
#include "interp/persist.hpp"

namespace {

namespace fs = std::filesystem;

using cnc_test::run_cnc;
using cnc_test::RunResult;
using cnc_test::ScratchDir;
using cnc_test::slurp;
using cnc_test::summary_axes;

const fs::path kSimDir = fs::path(CNC_SOURCE_DIR) / "configs/sim";

// One machine's state folder and the programs run on configs/sim/mill.ini against it.
class Machine {
  public:
    fs::path settings_dir() const { return scratch_.path() / "state"; }
    fs::path file(const std::string& name) const { return settings_dir() / name; }

    RunResult run(const std::string& name, const std::string& program) const {
        const fs::path prog = scratch_.path() / name;
        std::ofstream(prog) << program;
        return run_cnc(fmt::format("configs/sim/mill.ini '{}' --sim-clock --settings-dir '{}'",
                                   prog.string(), settings_dir().string()),
                       scratch_.path());
    }

    const ScratchDir& scratch() const { return scratch_; }

  private:
    ScratchDir scratch_;
};

std::vector<double> final_xyz(const RunResult& r) {
    return summary_axes(r.out, "final position (mm)");
}

void expect_xyz(const RunResult& r, double x, double y, double z) {
    const std::vector<double> p = final_xyz(r);
    ASSERT_EQ(p.size(), 3u) << r.out << r.err;
    EXPECT_NEAR(p[0], x, 1e-6);
    EXPECT_NEAR(p[1], y, 1e-6);
    EXPECT_NEAR(p[2], z, 1e-6);
}

// The next run on `m`'s settings: `program` ends at machine X Y Z.
void expect_next_run_ends_at(const Machine& m, const std::string& program, double x, double y,
                             double z) {
    const RunResult use = m.run("use.ngc", program);
    ASSERT_EQ(use.exit_code, 0) << use.err << use.out;
    expect_xyz(use, x, y, z);
}

TEST(CncRunSettings, WorkOffsetSetInOneRunMovesTheNext) {
    const Machine m;
    const RunResult set = m.run("set.ngc", "G90 G21\nG922 P0 X10 Y20 Z-5\nM30\n");
    ASSERT_EQ(set.exit_code, 0) << set.err << set.out;
    expect_xyz(set, 0, 0, 0);  // writing an offset moves nothing
    EXPECT_NE(slurp(m.file("mill.var")).find("\nwcs 1 10 20 -5 0 0 0\n"), std::string::npos)
        << slurp(m.file("mill.var"));
    // why: G54's origin is now machine X10 Y20 Z-5, so work X5 Y5 Z0 is machine X15 Y25 Z-5.
    expect_next_run_ends_at(m, "G90 G21\nG54 G0 X5 Y5 Z0\nM30\n", 15, 25, -5);
}

TEST(CncRunSettings, G92ShiftPersists) {
    const Machine m;
    // why: at machine X0 Y0, G92 X-30 Y-40 makes the current point work X-30 Y-40: the shift
    // is +30 +40, so work X0 Y0 of the next run is machine X30 Y40.
    ASSERT_EQ(m.run("set.ngc", "G90 G21\nG92 X-30 Y-40\nM30\n").exit_code, 0);
    expect_next_run_ends_at(m, "G90 G21\nG0 X0 Y0\nM30\n", 30, 40, 0);
}

TEST(CncRunSettings, PersistentParameterWrittenInOneRunIsReadInTheNext) {
    const Machine m;
    ASSERT_EQ(m.run("set.ngc", "G90 G21\n#FIXEDCALI_REC = 12.5\nM30\n").exit_code, 0);
    EXPECT_NE(slurp(m.file("mill.var")).find("\nparam FIXEDCALI_REC 12.5\n"), std::string::npos);
    expect_next_run_ends_at(m, "G90 G21\nG0 X=#FIXEDCALI_REC\nM30\n", 12.5, 0, 0);
}

TEST(CncRunSettings, ToolLengthComesFromTheTable) {
    const Machine m;
    // why: T1 is 40 mm long in mill.tbl; under G43 H1 programmed Z-60 is machine Z-60+40 = -20.
    const RunResult r = m.run("tool.ngc", "G90 G21\nT1 M6\nG43 H1 G0 Z-60\nM30\n");
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    expect_xyz(r, 0, 0, -20);
    // Nothing changed, so nothing was written.
    EXPECT_FALSE(fs::exists(m.file("mill.tbl")));
    EXPECT_FALSE(fs::exists(m.file("mill.var")));
}

TEST(CncRunSettings, ToolLengthWrittenInOneRunIsUsedInTheNextAndTheShippedTableStays) {
    const std::string shipped = slurp(kSimDir / "mill.tbl");
    const Machine m;
    const RunResult set = m.run("set.ngc", "G90 G21\nG923 P1 Z30\nM30\n");
    ASSERT_EQ(set.exit_code, 0) << set.err << set.out;
    // The shipped table with T1's Z40 changed to Z30 and nothing else.
    EXPECT_EQ(slurp(m.file("mill.tbl")),
              "T1 P1 D6 Z30 ;6 mm flat end mill\n"
              "T2 P2 D3 Z35 ;3 mm flat end mill\n"
              "T3 P3 D6 Z45 ;6 mm ball end mill\n"
              "T4 P4 D10 Z50 ;10 mm drill\n");
    EXPECT_EQ(slurp(kSimDir / "mill.tbl"), shipped);
    // The settings file holds no tools while a tool table is kept.
    EXPECT_EQ(slurp(m.file("mill.var")).find("tool "), std::string::npos);
    // why: Z-60 + 30 = -30.
    expect_next_run_ends_at(m, "G90 G21\nT1 M6\nG43 H1 G0 Z-60\nM30\n", 0, 0, -30);
}

// A machine builder's hand-written table: G923 changes one number in it and adds the tool it
// creates at the end; every other byte stays (LinuxCNC's words we ignore, comments, order).
TEST(CncRunSettings, AHandWrittenToolTableKeepsEverythingButTheChangedValue) {
    const Machine m;
    fs::create_directories(m.settings_dir());
    const std::string hand =
        "; mill 3, tools measured 2026-11-02\n"
        ";T P  X Y Z   A B C U V W D  I J Q\n"
        "T4 P4 X0 Y0 Z50 A0 B0 C0 U0 V0 W0 D10 I0 J0 Q0 ;10 mm drill\n"
        "\n"
        "T2 P2 D3.000 Z35.000 Q2   ;  3 mm flat end mill\n"
        "t1 p1 d6 z+40 ;lower case\n";
    std::ofstream(m.file("mill.tbl")) << hand;
    const RunResult set = m.run("set.ngc", "G90 G21\nG923 P2 Z36.25\nG923 P9 Z12\nM30\n");
    ASSERT_EQ(set.exit_code, 0) << set.err << set.out;
    EXPECT_EQ(slurp(m.file("mill.tbl")),
              "; mill 3, tools measured 2026-11-02\n"
              ";T P  X Y Z   A B C U V W D  I J Q\n"
              "T4 P4 X0 Y0 Z50 A0 B0 C0 U0 V0 W0 D10 I0 J0 Q0 ;10 mm drill\n"
              "\n"
              "T2 P2 D3.000 Z36.25 Q2   ;  3 mm flat end mill\n"
              "t1 p1 d6 z+40 ;lower case\n"
              "T9 P9 Z12 D0\n");
    // why: T2 is now 36.25 mm long; Z-60 under G43 H2 is machine Z-60+36.25 = -23.75.
    expect_next_run_ends_at(m, "G90 G21\nT2 M6\nG43 H2 G0 Z-60\nM30\n", 0, 0, -23.75);
}

// A settings file a person wrote keeps its comments, order and spacing: G922 rewrites only the
// G54 line's words (before its comment), G92 adds the g92 line the file lacked at its end.
TEST(CncRunSettings, AHandWrittenSettingsFileKeepsEverythingButTheChangedEntry) {
    const Machine m;
    fs::create_directories(m.settings_dir());
    std::ofstream(m.file("mill.var")) << "# mill 3, set up by hand\n"
                                         "\n"
                                         "wcs 2 100 50 0 0 0 0  # vice\n"
                                         "wcs 1   5 5 0 0 0 0  # plate\n";
    const RunResult set = m.run("set.ngc", "G90 G21\nG922 P0 X10 Y20 Z-5\nG92 X-30\nM30\n");
    ASSERT_EQ(set.exit_code, 0) << set.err << set.out;
    // why: G92 X-30 at machine X0 under G54 (X10) makes work X-30 of machine X0: the shift is
    // 0 - 10 - (-30) = +20.
    EXPECT_EQ(slurp(m.file("mill.var")),
              "# mill 3, set up by hand\n"
              "\n"
              "wcs 2 100 50 0 0 0 0  # vice\n"
              "wcs 1 10 20 -5 0 0 0  # plate\n"
              "g92 20 0 0 0 0 0\n");
    // why: work X0 Y0 Z0 under G54 + G92 is machine X10+20 Y20 Z-5.
    expect_next_run_ends_at(m, "G90 G21\nG54 G0 X0 Y0 Z0\nM30\n", 30, 20, -5);
}

TEST(CncRunSettings, BadSettingsLineRefusesToStart) {
    const Machine m;
    fs::create_directories(m.settings_dir());
    const std::string bad = "wcs 1 10 20 0 0 0 0\nwcs 2 1 2 three 0 0 0\n";
    std::ofstream(m.file("mill.var")) << bad;
    const RunResult r = m.run("use.ngc", "G90 G21\nG0 X5\nM30\n");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, fmt::format("{}:2:11: settings: 'three' is not a number\n",
                                 m.file("mill.var").string()));
    EXPECT_EQ(r.out, "");  // nothing loaded, nothing moved
    EXPECT_EQ(slurp(m.file("mill.var")), bad);
}

TEST(CncRunSettings, BadToolTableLineRefusesToStart) {
    const Machine m;
    fs::create_directories(m.settings_dir());
    std::ofstream(m.file("mill.tbl")) << "T1 P1 Z40 D6\nT2 P2 Zx D3\n";
    const RunResult r = m.run("use.ngc", "G90 G21\nG0 X5\nM30\n");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err, fmt::format("{}:2:8: tool table: expected a number after 'Z'\n",
                                 m.file("mill.tbl").string()));
}

// A directory where the save's temporary file goes makes the save fail even for root.
TEST(CncRunSettings, FailedSaveIsAnErrorOfTheBlockAndKeepsTheOldFile) {
    const Machine m;
    ASSERT_EQ(m.run("set.ngc", "G90 G21\nG922 P0 X10 Y20\nM30\n").exit_code, 0);
    const std::string before = slurp(m.file("mill.var"));
    fs::create_directory(m.file("mill.var.tmp"));
    const RunResult r = m.run("change.ngc", "G90 G21\nG0 X5\nG922 P0 X1\nG0 X10\nM30\n");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find(fmt::format(
                  "change.ngc:3:1: settings not saved: {}: cannot create temporary settings "
                  "file: Is a directory (the file keeps its old contents)",
                  m.file("mill.var.tmp").string())),
              std::string::npos)
        << r.err;
    EXPECT_EQ(slurp(m.file("mill.var")), before);
    // With the obstacle gone the next run starts from the old offsets: work X0 = machine X10.
    fs::remove(m.file("mill.var.tmp"));
    expect_next_run_ends_at(m, "G90 G21\nG0 X0 Y0\nM30\n", 10, 20, 0);
}

// Two runs on the same settings at once: the second is refused before HAL loads (exit 2, a
// configuration error), naming the file and the first's process id, and its change is not
// saved. This test process holds the lock, as a first run would (interp::SettingsFileLock, the
// lock every run takes).
TEST(CncRunSettings, ASecondRunOnTheSameSettingsIsRefused) {
    const Machine m;
    ASSERT_EQ(m.run("set.ngc", "G90 G21\nG922 P0 X10\nM30\n").exit_code, 0);
    const std::string before = slurp(m.file("mill.var"));
    for (const std::string name : {"mill.var", "mill.tbl"}) {
        const interp::SettingsFileLock held(m.file(name).string());
        const RunResult r = m.run("change.ngc", "G90 G21\nG922 P0 X20\nG923 P1 Z30\nM30\n");
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_EQ(r.out.find("clock:"), std::string::npos) << r.out;  // no machine was started
        EXPECT_NE(r.err.find(fmt::format("{}: settings file in use by another run (pid {}); two "
                                         "runs on the same settings would overwrite each "
                                         "other's changes",
                                         m.file(name).string(), ::getpid())),
                  std::string::npos)
            << r.err;
        EXPECT_EQ(slurp(m.file("mill.var")), before);
        EXPECT_FALSE(fs::exists(m.file("mill.tbl")));
    }
    // Once the first run has let go the next one runs: G54 at X20, so work X0 is machine X20.
    ASSERT_EQ(m.run("change.ngc", "G90 G21\nG922 P0 X20\nG0 X0\nM30\n").exit_code, 0);
    expect_next_run_ends_at(m, "G90 G21\nG0 X0\nM30\n", 20, 0, 0);
}

// NcStudio's numbered variables #1-#999 are program-global (VAR-01): none is kept for the next
// run, #500-#999 included. Their persistence is Fanuc macro B's (FEATURES.md MAC-02, the ISO
// dialect's extension), which no manual gives NcStudio and the interpreter does not have yet.
TEST(CncRunSettings, NumberedVariablesStartUnsetInTheNextRun) {
    const Machine m;
    const RunResult set =
        m.run("set.ngc", "G90 G21\n#500 = 12.5\n#999 = 1\n#100 = 3\nG0 X=#500\nM30\n");
    ASSERT_EQ(set.exit_code, 0) << set.err << set.out;
    expect_xyz(set, 12.5, 0, 0);
    EXPECT_FALSE(fs::exists(m.file("mill.var")));  // nothing to keep, nothing written
    for (int n : {500, 999, 100}) {
        const RunResult use = m.run("use.ngc", fmt::format("G90 G21\nG0 X=#{}\nM30\n", n));
        EXPECT_EQ(use.exit_code, 1) << use.out;
        EXPECT_NE(
            use.err.find(fmt::format("use.ngc:2:6: variable #{} is used before it is set", n)),
            std::string::npos)
            << use.err;
    }
}

// An INI without [EMCIO]TOOL_TABLE keeps the tools in the settings file.
TEST(CncRunSettings, WithoutAToolTableTheToolsAreInTheSettingsFile) {
    const ScratchDir scratch;
    const fs::path ini = scratch.path() / "m.ini";
    std::ofstream(ini) << cnc_test::sim_ini("mill", [](const std::string&, std::string& line) {
        if (line.rfind("TOOL_TABLE = ", 0) == 0) line = "# no tool table";
    });
    const auto run = [&](const std::string& name, const std::string& program) {
        const fs::path prog = scratch.path() / name;
        std::ofstream(prog) << program;
        return run_cnc(fmt::format("'{}' '{}' --sim-clock", ini.string(), prog.string()),
                       scratch.path());
    };
    ASSERT_EQ(run("set.ngc", "G90 G21\nG923 P5 Z22\nM30\n").exit_code, 0);
    const fs::path settings = scratch.path() / "settings/mill.var";
    EXPECT_NE(slurp(settings).find("\ntool 5 0 0 22 0\n"), std::string::npos) << slurp(settings);
    EXPECT_FALSE(fs::exists(scratch.path() / "settings/mill.tbl"));
    // why: T5 is 22 mm long; Z-60 under G43 H5 is machine Z-38.
    const RunResult use = run("use.ngc", "G90 G21\nT5 M6\nG43 H5 G0 Z-60\nM30\n");
    ASSERT_EQ(use.exit_code, 0) << use.err << use.out;
    expect_xyz(use, 0, 0, -38);
}

// Without --settings-dir the files are where the INI says, relative to its folder (LinuxCNC):
// a config in a scratch folder gets its settings file and tool table written beside it.
TEST(CncRunSettings, WithoutSettingsDirTheFilesAreBesideTheIni) {
    const ScratchDir scratch;
    const fs::path config = scratch.path() / "machine";
    fs::create_directories(config);
    std::ofstream(config / "m.ini")
        << cnc_test::sim_ini("mill", [](const std::string&, std::string& line) {
               if (line.rfind("PARAMETER_FILE = ", 0) == 0) line = "PARAMETER_FILE = state/m.var";
               if (line.rfind("TOOL_TABLE = ", 0) == 0) line = "TOOL_TABLE = m.tbl";
           });
    fs::create_directories(config / "state");
    std::ofstream(config / "m.tbl") << "T7 P3 Z12.5 D2 ;engraver\n";
    const fs::path prog = scratch.path() / "p.ngc";
    std::ofstream(prog) << "G90 G21\nG922 P1 X7\nG923 P7 Z20\nM30\n";
    // An empty --settings-dir is no folder: the INI's own paths.
    const RunResult r = run_cnc(fmt::format("'{}' '{}' --sim-clock --settings-dir ''",
                                            (config / "m.ini").string(), prog.string()),
                                scratch.path());
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
    EXPECT_NE(slurp(config / "state/m.var").find("\nwcs 2 7 0 0 0 0 0\n"), std::string::npos);
    EXPECT_EQ(slurp(config / "m.tbl"), "T7 P3 Z20 D2 ;engraver\n");
}

}  // namespace

// `cnc canon --settings FILE --save-settings` writes the same files a machine does, so it takes
// the same lock: refused (setup error, exit 2, nothing run or written) while another process
// holds FILE, and saves once it is free.
TEST(CncCanonSettings, SavingSettingsTakesTheRunLock) {
    const ScratchDir scratch;
    const fs::path settings = scratch.path() / "settings.txt";
    const fs::path prog = scratch.path() / "g92.ngc";
    std::ofstream(settings) << "wcs 2 100 0 0 0 0 0\n";
    std::ofstream(prog) << "G90 G21\nG0 X10 Y20\nG92 X0 Y0\nM30\n";
    const std::string cmd =
        fmt::format("'{}' canon '{}' --settings '{}' --save-settings > '{}' 2> '{}'", CNC_BIN,
                    prog.string(), settings.string(), (scratch.path() / "out.txt").string(),
                    (scratch.path() / "err.txt").string());
    {
        const interp::SettingsFileLock held(settings.string());
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status));
        EXPECT_EQ(WEXITSTATUS(status), 2);
        EXPECT_NE(slurp(scratch.path() / "err.txt")
                      .find(fmt::format("{}: settings file in use by another run (pid {})",
                                        settings.string(), ::getpid())),
                  std::string::npos)
            << slurp(scratch.path() / "err.txt");
        EXPECT_EQ(slurp(settings), "wcs 2 100 0 0 0 0 0\n");
    }
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << slurp(scratch.path() / "err.txt");
    EXPECT_NE(slurp(settings).find("g92 10 20 0 0 0 0\n"), std::string::npos) << slurp(settings);
}
