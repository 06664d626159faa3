// The machine builder's interpreter options (machine_program::Options) from the [RS274NGC]
// section of the machine's INI. Read by the components that run programs (interp, and motion
// with program=) from their ini= argument, and by `cnc run` before it loads anything, so a bad
// value is reported once as `file:line: [RS274NGC]KEY = value: cause`. Configuration world.
#pragma once

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "hal/ini.hpp"
#include "hal/types.hpp"
#include "machine_program.hpp"

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

}  // namespace ini_detail

// The [RS274NGC] options of `ini`. A key given twice counts once, the first time (as
// IniFile::get). Throws hal::Error naming the INI line of a bad value.
inline Options read_ini(const hal::IniFile& ini) {
    Options o;
    for (const ini_detail::Key& k : ini_detail::kKeys)
        if (const auto* e = ini.find("RS274NGC", k.name)) k.apply(*e, o);
    if (o.use_default_speed && o.default_feed_mm_min <= 0)
        ini_detail::bad_value(
            *ini.find("RS274NGC", "USE_DEFAULT_SPEED"),
            "needs [RS274NGC]DEFAULT_FEED_MM_MIN > 0, the speed every feed move then runs at");
    return o;
}

// A component's options from its loadrt arguments: ini= (the machine's INI; its [RS274NGC]
// section) and dialect= (wins over the INI's DIALECT). Neither given: the defaults.
inline Options options_from_args(const std::optional<std::string>& ini_path,
                                 const std::optional<std::string>& dialect) {
    Options o =
        ini_path && !ini_path->empty() ? read_ini(hal::IniFile::load(*ini_path)) : Options{};
    if (dialect && !dialect->empty()) {
        if (!interp::find_dialect(*dialect))
            throw hal::Error(fmt::format("dialect={}: unknown dialect", *dialect));
        o.dialect = *dialect;
    }
    return o;
}

}  // namespace machine_program
