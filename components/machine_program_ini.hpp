// The machine builder's interpreter options (machine_program::Options) from the [RS274NGC]
// section of the machine's INI, and the files it keeps the interpreter's state in
// ([RS274NGC]PARAMETER_FILE, [EMCIO]TOOL_TABLE), read here too. Read by the components that
// run programs (interp, and motion with program=) from their ini= argument, and by `cnc run`
// before it loads anything, so a bad value is reported once as `file:line: [RS274NGC]KEY =
// value: cause` and a bad settings line as `file:line:col: cause`. Configuration world.
#pragma once

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "hal/ini.hpp"
#include "hal/types.hpp"
#include "machine_program.hpp"
#include "machine_state.hpp"

namespace machine_program {

namespace ini_detail {

using Entry = hal::IniFile::Entry;

[[noreturn]] inline void bad_value(const Entry& e, std::string_view cause) {
    throw hal::Error(
        fmt::format("{}:{}: [{}]{} = {}: {}", e.file, e.line, e.section, e.key, e.value, cause));
}

// 0/1 as LinuxCNC's INIs write switches; TRUE/FALSE, YES/NO and ON/OFF too (any case).
inline bool switch_value(const Entry& e) {
    std::string v;
    for (char c : e.value) v += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (v == "1" || v == "TRUE" || v == "YES" || v == "ON") return true;
    if (v == "0" || v == "FALSE" || v == "NO" || v == "OFF") return false;
    bad_value(e, "expected 0 or 1");
}

inline double number_value(const Entry& e) {
    double v = 0;
    const char* end = e.value.data() + e.value.size();
    const auto [ptr, ec] = std::from_chars(e.value.data(), end, v);
    if (e.value.empty() || ec != std::errc{} || ptr != end || !std::isfinite(v))
        bad_value(e, "expected a number");
    return v;
}

inline double at_least_zero(const Entry& e, std::string_view unit) {
    const double v = number_value(e);
    if (v < 0) bad_value(e, fmt::format("must be 0 or more ({}; 0 = none)", unit));
    return v;
}

struct Key {
    const char* name;
    void (*apply)(const Entry&, Options&);
};

// One entry per key; a key the table does not name is left to whoever reads it (LinuxCNC's
// PARAMETER_FILE, SUBROUTINE_PATH, … share the section).
inline constexpr Key kKeys[] = {
    {"DIALECT",
     [](const Entry& e, Options& o) {
         if (!interp::find_dialect(e.value))
             bad_value(e, "unknown dialect (ncstudio, ncstudio-v54 or ncstudio-c-logic)");
         o.dialect = e.value;
     }},
    {"DEFAULT_FEED_MM_MIN",
     [](const Entry& e, Options& o) { o.default_feed_mm_min = at_least_zero(e, "mm/min"); }},
    {"USE_DEFAULT_SPEED",
     [](const Entry& e, Options& o) { o.use_default_speed = switch_value(e); }},
    {"MAX_FEED_MM_MIN",
     [](const Entry& e, Options& o) { o.max_feed_mm_min = at_least_zero(e, "mm/min"); }},
    {"MAX_RAPID_MM_MIN",
     [](const Entry& e, Options& o) { o.max_rapid_mm_min = at_least_zero(e, "mm/min"); }},
    {"G00_Z_SPLIT", [](const Entry& e, Options& o) { o.g00_z_split = switch_value(e); }},
    {"IJK_INCREMENTAL", [](const Entry& e, Options& o) { o.ijk_incremental = switch_value(e); }},
    {"ARC_TOLERANCE_MM",
     [](const Entry& e, Options& o) {
         o.arc_tolerance_mm = number_value(e);
         if (!(o.arc_tolerance_mm > 0)) bad_value(e, "must be more than 0 (mm)");
     }},
    {"T_CHANGES_TOOL", [](const Entry& e, Options& o) { o.t_changes_tool = switch_value(e); }},
    {"END_STOPS_SPINDLE",
     [](const Entry& e, Options& o) { o.end_stops_spindle = switch_value(e); }},
    {"S_HOOK_PROGRAM",
     [](const Entry& e, Options& o) {
         const double n = number_value(e);
         if (n < 1 || n > 99999999 || n != std::floor(n))
             bad_value(e, "expected a program number (a whole number, 1 to 99999999)");
         o.s_hook_program = static_cast<std::int64_t>(n);
     }},
};

// The file an INI entry names, relative to the INI's folder (as LinuxCNC resolves it).
inline std::filesystem::path config_file(const hal::IniFile& ini, const Entry& e) {
    const std::filesystem::path given(e.value);
    if (given.filename().empty()) bad_value(e, "expected a file name");
    return given.is_absolute() ? given : std::filesystem::path(ini.path()).parent_path() / given;
}

// `[section]key` (config_file) into `file`; with a settings folder, `file` is the file of that
// name in the folder and the INI's file only its `seed`.
inline void place_state_file(const hal::IniFile& ini, const char* section, const char* key,
                             const std::string& settings_dir, std::string& file,
                             std::string& seed) {
    namespace fs = std::filesystem;
    const Entry* e = ini.find(section, key);
    if (!e) return;
    const fs::path given(e->value);
    const fs::path in_config = config_file(ini, *e);
    if (settings_dir.empty()) {
        file = in_config.string();
        return;
    }
    file = (fs::path(settings_dir) / given.filename()).string();
    seed = in_config.string();
}

}  // namespace ini_detail

// Where the INI keeps the interpreter's state; `settings_dir` non-empty takes the writes (see
// StateFiles). Throws hal::Error naming the INI line of a bad value.
inline StateFiles state_files(const hal::IniFile& ini, const std::string& settings_dir = "") {
    StateFiles f;
    ini_detail::place_state_file(ini, "RS274NGC", "PARAMETER_FILE", settings_dir, f.settings,
                                 f.settings_seed);
    ini_detail::place_state_file(ini, "EMCIO", "TOOL_TABLE", settings_dir, f.tool_table,
                                 f.tool_table_seed);
    if (!f.settings.empty() && f.settings == f.tool_table)
        ini_detail::bad_value(*ini.find("EMCIO", "TOOL_TABLE"),
                              "the same file as [RS274NGC]PARAMETER_FILE");
    return f;
}

// The [RS274NGC] options of `ini` (LIBRARY: public.dat, relative to the INI's folder), with the
// state its files hold (state_files, load_state). A
// key given twice counts once, the first time (as IniFile::get). Throws hal::Error naming the
// INI line of a bad value, or the settings file's or tool table's line.
inline Options read_ini(const hal::IniFile& ini, const std::string& settings_dir = "") {
    Options o;
    o.state = state_files(ini, settings_dir);
    try {
        o.settings = load_state(o.state);
    } catch (const interp::Error& e) {
        throw hal::Error(e.what());
    }
    for (const ini_detail::Key& k : ini_detail::kKeys)
        if (const auto* e = ini.find("RS274NGC", k.name)) k.apply(*e, o);
    if (const auto* e = ini.find("RS274NGC", "LIBRARY")) {
        const std::filesystem::path lib = ini_detail::config_file(ini, *e);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(lib, ec))
            ini_detail::bad_value(*e, fmt::format("{}: no such file", lib.string()));
        o.library = lib.string();
    }
    if (o.use_default_speed && o.default_feed_mm_min <= 0)
        ini_detail::bad_value(
            *ini.find("RS274NGC", "USE_DEFAULT_SPEED"),
            "needs [RS274NGC]DEFAULT_FEED_MM_MIN > 0, the speed every feed move then runs at");
    return o;
}

// A component's options from its loadrt arguments: ini= (the machine's INI; its [RS274NGC]
// section and state files), dialect= (wins over the INI's DIALECT) and settings_dir= (where
// the state files are written; see StateFiles). None given: the defaults, nothing kept.
inline Options options_from_args(const std::optional<std::string>& ini_path,
                                 const std::optional<std::string>& dialect,
                                 const std::optional<std::string>& settings_dir = std::nullopt) {
    const bool has_ini = ini_path && !ini_path->empty();
    const std::string dir = settings_dir.value_or("");
    if (!dir.empty() && !has_ini)
        throw hal::Error(fmt::format(
            "settings_dir={}: needs ini= (the INI names the settings file and tool table)", dir));
    Options o = has_ini ? read_ini(hal::IniFile::load(*ini_path), dir) : Options{};
    if (dialect && !dialect->empty()) {
        if (!interp::find_dialect(*dialect))
            throw hal::Error(fmt::format("dialect={}: unknown dialect", *dialect));
        o.dialect = *dialect;
    }
    return o;
}

}  // namespace machine_program
