// The machine's interpreter options from [RS274NGC] (components/machine_program_ini.hpp): every
// key reaches the BackendConfig / InterpreterOptions both program paths build, and every bad
// value is refused with the INI's file:line and the cause.
#include <gtest/gtest.h>

#include <string>

#include "hal/ini.hpp"
#include "hal/types.hpp"
#include "machine_program_ini.hpp"

namespace {

using machine_program::Options;

Options options_of(const std::string& section_body) {
    return machine_program::read_ini(
        hal::IniFile::parse("[EMC]\nMACHINE = t\n[RS274NGC]\n" + section_body, "m.ini"));
}

std::string error_of(const std::string& section_body) {
    try {
        options_of(section_body);
    } catch (const hal::Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(MachineProgramIni, NoKeysGiveCncCanonsDefaults) {
    const Options o = options_of("");
    EXPECT_EQ(o, Options{});
    const interp::BackendConfig b = machine_program::backend_config(o);
    const interp::BackendConfig plain;
    EXPECT_TRUE(b.optional_stop);  // motion decides with motion.optional-stop
    EXPECT_EQ(b.default_feed_mm_s, 0);
    EXPECT_FALSE(b.use_default_speed);
    EXPECT_EQ(b.g00_z_split, plain.g00_z_split);
    EXPECT_EQ(b.ijk_incremental, plain.ijk_incremental);
    EXPECT_EQ(b.arc_tolerance_mm, plain.arc_tolerance_mm);
    EXPECT_EQ(b.t_changes_tool, plain.t_changes_tool);
    EXPECT_FALSE(b.v54_compat);
    const interp::InterpreterOptions i = machine_program::interpreter_options(o);
    EXPECT_EQ(i.dialect, &interp::ncstudio_dialect());
    EXPECT_FALSE(i.main_m99_loops);
    EXPECT_FALSE(i.s_hook_program);
}

TEST(MachineProgramIni, EveryKeyReachesTheInterpreter) {
    const Options o = options_of(
        "DIALECT = ncstudio-v54\n"
        "DEFAULT_FEED_MM_MIN = 600\n"
        "USE_DEFAULT_SPEED = yes\n"
        "MAX_FEED_MM_MIN = 6000\n"
        "MAX_RAPID_MM_MIN = 12000\n"
        "G00_Z_SPLIT = 0\n"
        "IJK_INCREMENTAL = FALSE\n"
        "ARC_TOLERANCE_MM = 0.002\n"
        "T_CHANGES_TOOL = 1\n"
        "END_STOPS_SPINDLE = off\n"
        "S_HOOK_PROGRAM = 9001\n"
        "PARAMETER_FILE = sim.var\n");  // no such file here: the default settings
    const interp::BackendConfig b = machine_program::backend_config(o);
    EXPECT_TRUE(b.v54_compat);
    EXPECT_DOUBLE_EQ(b.default_feed_mm_s, 10);  // 600 / 60
    EXPECT_TRUE(b.use_default_speed);
    EXPECT_DOUBLE_EQ(b.max_feed_mm_s, 100);
    EXPECT_DOUBLE_EQ(b.max_rapid_mm_s, 200);
    EXPECT_FALSE(b.g00_z_split);
    EXPECT_FALSE(b.ijk_incremental);
    EXPECT_DOUBLE_EQ(b.arc_tolerance_mm, 0.002);
    EXPECT_TRUE(b.t_changes_tool);  // set, although V5.4's default is M06
    EXPECT_FALSE(b.end_stops_spindle);
    const interp::InterpreterOptions i = machine_program::interpreter_options(o);
    EXPECT_EQ(i.dialect, &interp::ncstudio_v54_dialect());
    EXPECT_EQ(i.s_hook_program, 9001);
}

// As `cnc canon --dialect ncstudio-v54`: M06 changes the tool unless the INI says otherwise.
TEST(MachineProgramIni, V54DialectChangesTheToolAtM06ByDefault) {
    EXPECT_FALSE(
        machine_program::backend_config(options_of("DIALECT = ncstudio-v54\n")).t_changes_tool);
}

TEST(MachineProgramIni, FirstOfARepeatedKeyCounts) {
    EXPECT_EQ(
        options_of("DEFAULT_FEED_MM_MIN = 100\nDEFAULT_FEED_MM_MIN = 200\n").default_feed_mm_min,
        100);
}

TEST(MachineProgramIni, DialectArgumentWinsOverTheIni) {
    EXPECT_EQ(machine_program::options_from_args(std::nullopt, std::string("ncstudio-v54")).dialect,
              "ncstudio-v54");
    EXPECT_EQ(machine_program::options_from_args(std::nullopt, std::nullopt), Options{});
    try {
        machine_program::options_from_args(std::nullopt, std::string("fanuc"));
        FAIL() << "no error";
    } catch (const hal::Error& e) {
        EXPECT_STREQ(e.what(), "dialect=fanuc: unknown dialect");
    }
}

// One line per message; the key is on line 4 (after [EMC], MACHINE and [RS274NGC]).
TEST(MachineProgramIni, OneTestPerErrorMessage) {
    EXPECT_EQ(error_of("DIALECT = fanuc\n"),
              "m.ini:4: [RS274NGC]DIALECT = fanuc: unknown dialect (ncstudio, ncstudio-v54 or "
              "ncstudio-c-logic)");
    EXPECT_EQ(error_of("USE_DEFAULT_SPEED = 2\n"),
              "m.ini:4: [RS274NGC]USE_DEFAULT_SPEED = 2: expected 0 or 1");
    EXPECT_EQ(error_of("DEFAULT_FEED_MM_MIN = 600mm\n"),
              "m.ini:4: [RS274NGC]DEFAULT_FEED_MM_MIN = 600mm: expected a number");
    EXPECT_EQ(error_of("MAX_FEED_MM_MIN =\n"),
              "m.ini:4: [RS274NGC]MAX_FEED_MM_MIN = : expected a number");
    EXPECT_EQ(error_of("MAX_RAPID_MM_MIN = -1\n"),
              "m.ini:4: [RS274NGC]MAX_RAPID_MM_MIN = -1: must be 0 or more (mm/min; 0 = none)");
    EXPECT_EQ(error_of("ARC_TOLERANCE_MM = 0\n"),
              "m.ini:4: [RS274NGC]ARC_TOLERANCE_MM = 0: must be more than 0 (mm)");
    EXPECT_EQ(error_of("S_HOOK_PROGRAM = 12.5\n"),
              "m.ini:4: [RS274NGC]S_HOOK_PROGRAM = 12.5: expected a program number (a whole "
              "number, 1 to 99999999)");
    EXPECT_EQ(error_of("DEFAULT_FEED_MM_MIN = 0\nUSE_DEFAULT_SPEED = 1\n"),
              "m.ini:5: [RS274NGC]USE_DEFAULT_SPEED = 1: needs [RS274NGC]DEFAULT_FEED_MM_MIN > 0, "
              "the speed every feed move then runs at");
    EXPECT_EQ(error_of("G00_Z_SPLIT = nan\n"),
              "m.ini:4: [RS274NGC]G00_Z_SPLIT = nan: expected 0 or 1");
    EXPECT_EQ(error_of("ARC_TOLERANCE_MM = inf\n"),
              "m.ini:4: [RS274NGC]ARC_TOLERANCE_MM = inf: expected a number");
}

}  // namespace
