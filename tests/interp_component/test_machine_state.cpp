// Where a machine keeps the interpreter's state (components/machine_program_ini.hpp
// state_files: [RS274NGC]PARAMETER_FILE and [EMCIO]TOOL_TABLE relative to the INI's folder,
// a settings folder taking the writes) and how it is read and written back
// (components/machine_state.hpp: load_state, StateSaver). End to end: tests/cnc_run
// test_cnc_run_settings.cpp and tests/hal/interp-settings-*.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "hal/ini.hpp"
#include "hal/types.hpp"
#include "machine_program_ini.hpp"
#include "machine_state.hpp"
#include "scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using machine_program::StateFiles;

hal::IniFile ini_of(const std::string& text, const std::string& name = "/cfg/m.ini") {
    return hal::IniFile::parse(text, name);
}

std::string error_of(const std::string& text, const std::string& settings_dir = "") {
    try {
        machine_program::state_files(ini_of(text, "m.ini"), settings_dir);
    } catch (const hal::Error& e) {
        return e.what();
    }
    return "no error";
}

// Each test's own folder, removed after it.
class Folder : public ::testing::Test {
  protected:
    cnc_test::ScratchDir scratch_;
    const fs::path& dir_ = scratch_.path();
};

TEST(MachineStateFiles, RelativeToTheIniFolderAbsoluteAsGiven) {
    const StateFiles f = machine_program::state_files(
        ini_of("[RS274NGC]\nPARAMETER_FILE = sub/m.var\n[EMCIO]\nTOOL_TABLE = /tools/t.tbl\n"));
    EXPECT_EQ(f.settings, "/cfg/sub/m.var");
    EXPECT_EQ(f.tool_table, "/tools/t.tbl");
    EXPECT_EQ(f.settings_seed, "");
    EXPECT_EQ(f.tool_table_seed, "");
}

TEST(MachineStateFiles, ASettingsFolderTakesTheFilesByNameAndSeedsFromTheIni) {
    const StateFiles f = machine_program::state_files(
        ini_of("[RS274NGC]\nPARAMETER_FILE = sub/m.var\n[EMCIO]\nTOOL_TABLE = /tools/t.tbl\n"),
        "/state");
    EXPECT_EQ(f.settings, "/state/m.var");
    EXPECT_EQ(f.settings_seed, "/cfg/sub/m.var");
    EXPECT_EQ(f.tool_table, "/state/t.tbl");
    EXPECT_EQ(f.tool_table_seed, "/tools/t.tbl");
}

TEST(MachineStateFiles, NoKeysKeepNothing) {
    EXPECT_EQ(machine_program::state_files(ini_of("[RS274NGC]\nDIALECT = ncstudio\n"), "/state"),
              StateFiles{});
}

TEST(MachineStateFiles, BadPathsNameTheIniLine) {
    EXPECT_EQ(error_of("[RS274NGC]\nPARAMETER_FILE =\n"),
              "m.ini:2: [RS274NGC]PARAMETER_FILE = : expected a file name");
    EXPECT_EQ(error_of("[EMCIO]\nTOOL_TABLE = tools/\n"),
              "m.ini:2: [EMCIO]TOOL_TABLE = tools/: expected a file name");
    EXPECT_EQ(
        error_of("[RS274NGC]\nPARAMETER_FILE = a/x.dat\n[EMCIO]\nTOOL_TABLE = b/x.dat\n", "/state"),
        "m.ini:4: [EMCIO]TOOL_TABLE = b/x.dat: the same file as [RS274NGC]PARAMETER_FILE");
}

TEST_F(Folder, TheFileWinsOverItsSeedAndMissingFilesGiveTheDefaults) {
    StateFiles f;
    f.settings = (dir_ / "state.var").string();
    f.settings_seed = (dir_ / "seed.var").string();
    f.tool_table = (dir_ / "state.tbl").string();
    f.tool_table_seed = (dir_ / "seed.tbl").string();
    EXPECT_EQ(machine_program::load_state(f), interp::Settings{});
    std::ofstream(f.settings_seed) << "wcs 1 5 0 0 0 0 0\n";
    std::ofstream(f.tool_table_seed) << "T1 P1 Z40 D6\n";
    interp::Settings s = machine_program::load_state(f);
    EXPECT_EQ(s.offsets.wcs[0][0], 5);
    ASSERT_NE(s.tools.find(1), nullptr);
    EXPECT_EQ(s.tools.find(1)->offset_mm[2], 40);
    std::ofstream(f.settings) << "wcs 1 9 0 0 0 0 0\ntool 1 0 0 11 0\ntool 2 0 0 22 0\n";
    s = machine_program::load_state(f);
    EXPECT_EQ(s.offsets.wcs[0][0], 9);
    EXPECT_EQ(s.tools.find(1)->offset_mm[2], 40);  // the table's tool wins
    EXPECT_EQ(s.tools.find(2)->offset_mm[2], 22);  // one only the settings file has stays
}

TEST_F(Folder, AToolTableThatIsAFolderIsAnError) {
    StateFiles f;
    f.tool_table = dir_.string();
    try {
        machine_program::load_state(f);
        FAIL() << "no error";
    } catch (const interp::Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  dir_.string() + ":0:0: tool table: cannot read file: Is a directory");
    }
}

// Only the file whose part changed is written; with a tool table the settings file has no tools.
TEST_F(Folder, OnlyWhatChangedIsWritten) {
    StateFiles f;
    f.settings = (dir_ / "m.var").string();
    f.tool_table = (dir_ / "t.tbl").string();
    interp::Settings s;
    s.tools.at(1).offset_mm = {0, 0, 40};
    s.tools.at(1).diameter_mm = 6;
    machine_program::StateSaver saver(f, s);
    saver.save(s);
    EXPECT_FALSE(fs::exists(f.settings));
    EXPECT_FALSE(fs::exists(f.tool_table));
    s.tools.at(1).offset_mm[2] = 30;
    saver.save(s);
    EXPECT_EQ(cnc_test::slurp(f.tool_table), "T1 P1 Z30 D6\n");
    EXPECT_FALSE(fs::exists(f.settings));
    s.offsets.g92[0] = 2.5;
    saver.save(s);
    const std::string var = cnc_test::slurp(f.settings);
    EXPECT_NE(var.find("\ng92 2.5 0 0 0 0 0\n"), std::string::npos) << var;
    EXPECT_EQ(var.find("tool"), std::string::npos) << var;
    fs::remove(f.tool_table);
    s.params["FIXEDCALI_REC"] = 1;
    saver.save(s);  // the tools did not change: the table is not written again
    EXPECT_FALSE(fs::exists(f.tool_table));
}

// A machine builder's hand-written table survives a save by the machine's own path (load_state,
// then StateSaver): every line as written but the one changed number. The expected file is the
// seed with "Z35" replaced by "Z36.25" by hand.
TEST_F(Folder, AHandWrittenToolTableKeepsEverythingButTheChangedValue) {
    const std::string hand =
        "; Smith mill\n"
        "T3 P3 X0.5 Y0 Z45 A0 B0 C0 U0 V0 W0 D6 I0 J0 Q0 ;ball end mill\n"
        "\n"
        "T1 P1 Z35 D3 Q1 ;drill\n";
    StateFiles f;
    f.settings = (dir_ / "m.var").string();
    f.tool_table = (dir_ / "t.tbl").string();
    f.tool_table_seed = (dir_ / "seed.tbl").string();
    std::ofstream(f.tool_table_seed) << hand;
    interp::Settings s = machine_program::load_state(f);
    machine_program::StateSaver saver(f, s);
    s.tools.at(1).offset_mm[2] = 36.25;
    saver.save(s);
    EXPECT_EQ(cnc_test::slurp(f.tool_table),
              "; Smith mill\n"
              "T3 P3 X0.5 Y0 Z45 A0 B0 C0 U0 V0 W0 D6 I0 J0 Q0 ;ball end mill\n"
              "\n"
              "T1 P1 Z36.25 D3 Q1 ;drill\n");
    EXPECT_EQ(cnc_test::slurp(f.tool_table_seed), hand);
    EXPECT_FALSE(fs::exists(f.settings));
    // A tool the program creates goes at the end.
    s.tools.at(2).offset_mm[2] = 20;
    saver.save(s);
    EXPECT_EQ(cnc_test::slurp(f.tool_table),
              "; Smith mill\n"
              "T3 P3 X0.5 Y0 Z45 A0 B0 C0 U0 V0 W0 D6 I0 J0 Q0 ;ball end mill\n"
              "\n"
              "T1 P1 Z36.25 D3 Q1 ;drill\n"
              "T2 P2 Z20 D0\n");
}

// A tool only the settings file lists (the INI named no tool table before) is not lost when an
// offset is saved: its line stays until a tool save carries it into the table.
TEST_F(Folder, AnOffsetSaveKeepsAToolOnlyTheSettingsFileLists) {
    StateFiles f;
    f.settings = (dir_ / "m.var").string();
    f.tool_table = (dir_ / "t.tbl").string();
    std::ofstream(f.settings) << "tool 2 0 0 22 0\n";
    std::ofstream(f.tool_table) << "T1 P1 Z40 D6\n";
    interp::Settings s = machine_program::load_state(f);
    machine_program::StateSaver saver(f, s);
    s.offsets.g92[0] = 1;
    saver.save(s);
    EXPECT_EQ(cnc_test::slurp(f.settings), "tool 2 0 0 22 0\ng92 1 0 0 0 0 0\n");
    ASSERT_NE(machine_program::load_state(f).tools.find(2), nullptr);
    s.tools.at(1).offset_mm[2] = 41;
    saver.save(s);
    EXPECT_EQ(cnc_test::slurp(f.tool_table), "T1 P1 Z41 D6\nT2 P2 Z22 D0\n");
}

// Two of the stock sim machines can run at once without a settings folder: a run locks its
// settings file and tool table, so any file two of them shared would keep the second out.
TEST(MachineStateFiles, EveryStockSimMachineKeepsItsOwnFiles) {
    std::set<std::string> seen;
    int machines = 0;
    for (const fs::directory_entry& e :
         fs::directory_iterator(fs::path(CNC_SOURCE_DIR) / "configs/sim")) {
        if (e.path().extension() != ".ini") continue;
        ++machines;
        const StateFiles f =
            machine_program::state_files(hal::IniFile::load(e.path().string()));
        ASSERT_FALSE(f.settings.empty()) << e.path();
        ASSERT_FALSE(f.tool_table.empty()) << e.path();
        EXPECT_TRUE(fs::exists(f.tool_table)) << e.path() << " names " << f.tool_table;
        EXPECT_TRUE(seen.insert(fs::weakly_canonical(f.settings).string()).second)
            << e.path() << " shares " << f.settings;
        EXPECT_TRUE(seen.insert(fs::weakly_canonical(f.tool_table).string()).second)
            << e.path() << " shares " << f.tool_table;
    }
    EXPECT_GE(machines, 5);
}

}  // namespace
