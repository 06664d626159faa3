// How a program is interpreted for a machine, in one place for both ways motion can get it:
// the interp component's runner (canon= stream) and motion's own program feeder (program=).
// Both must produce the same canonical stream, so they share these settings. The machine
// builder's part of them comes from the [RS274NGC] section of the machine's INI
// (machine_program_ini.hpp reads it); the rest is fixed here for every machine.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "interp/dialect.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace machine_program {

// Where a machine keeps what the interpreter remembers between runs: the settings file (work
// offsets, G92, persistent named parameters; [RS274NGC]PARAMETER_FILE) and the tool table
// (tool lengths and diameters; [EMCIO]TOOL_TABLE). Empty: not kept. While a file does not
// exist yet its `_seed` is read in its place (the INI's own file, when a settings folder takes
// the writes); neither existing gives the defaults. machine_state.hpp reads and writes them.
struct StateFiles {
    std::string settings;
    std::string settings_seed;
    std::string tool_table;
    std::string tool_table_seed;

    bool operator==(const StateFiles&) const = default;
};

// What a machine builder chooses about the interpreter. Unset optionals take the dialect's
// default; the rest default as `cnc canon` does without options.
struct Options {
    std::string dialect;                 // empty: ncstudio
    double default_feed_mm_min = 0;      // feed moves before any F; 0 = such a move is an error
    bool use_default_speed = false;      // G00-4: moves ignore F (G905 blocks excepted)
    double max_feed_mm_min = 0;          // FEED-8 clamp for cutting feeds; 0 = none
    double max_rapid_mm_min = 0;         // clamp for F in G00 blocks; 0 = none
    bool g00_z_split = true;             // G00-2: NcStudio's Z-first/Z-last rapid
    bool ijk_incremental = true;         // ARC-5: I J K relative to the arc start
    double arc_tolerance_mm = 0.01;      // ARC-11
    std::optional<bool> t_changes_tool;  // M06-1: 6th edition yes, V5.4 no (M06 changes)
    bool end_stops_spindle = true;       // M02/M30 stop spindle and coolant
    std::optional<std::int64_t> s_hook_program;  // CUS-4: O-number run after each S block
    std::string library;                         // public.dat ([RS274NGC]LIBRARY); "" = none
    StateFiles state;                            // where the settings are kept
    interp::Settings settings;                   // as read from `state` with the options

    bool operator==(const Options&) const = default;
};

inline bool is_v54(const Options& o) {
    return o.dialect == "ncstudio-v54";
}

inline interp::InterpreterOptions interpreter_options(const Options& o) {
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping main program would run forever on a machine
    if (!o.dialect.empty()) options.dialect = interp::find_dialect(o.dialect);
    options.s_hook_program = o.s_hook_program;
    return options;
}

// Opens `program` as the machine runs it: with the machine's public.dat library, as
// `cnc canon -l` does. Throws interp::Error "file:line:col: cause".
inline void open_program(interp::Interpreter& in, const Options& o, const std::string& program) {
    if (!o.library.empty()) in.load_library(o.library);
    in.open(program);
}

// The same derivations from the dialect as `cnc canon --dialect`, so a program runs on the
// machine as it prints.
inline interp::BackendConfig backend_config(const Options& o) {
    interp::BackendConfig backend;
    backend.optional_stop = true;  // M01 reaches motion, which obeys motion.optional-stop
    // As `cnc canon --dialect ncstudio-v54`: V5.4's M10/M11 clamp, M902 sets 0, M06 changes.
    backend.v54_compat = is_v54(o);
    backend.t_changes_tool = o.t_changes_tool.value_or(!backend.v54_compat);  // C-29
    backend.default_feed_mm_s = o.default_feed_mm_min / 60.0;
    backend.use_default_speed = o.use_default_speed;
    backend.max_feed_mm_s = o.max_feed_mm_min / 60.0;
    backend.max_rapid_mm_s = o.max_rapid_mm_min / 60.0;
    backend.g00_z_split = o.g00_z_split;
    backend.ijk_incremental = o.ijk_incremental;
    backend.arc_tolerance_mm = o.arc_tolerance_mm;
    backend.end_stops_spindle = o.end_stops_spindle;
    return backend;
}

}  // namespace machine_program
