// How a program is interpreted for a machine, in one place for both ways motion can get it:
// the interp component's runner (canon= stream) and motion's own program feeder (program=).
// Both must produce the same canonical stream, so they share these settings.
#pragma once

#include <string>

#include "interp/dialect.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace machine_program {

inline interp::InterpreterOptions interpreter_options(const std::string& dialect) {
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping main program would run forever on a machine
    if (!dialect.empty()) options.dialect = interp::find_dialect(dialect);
    return options;
}

inline interp::BackendConfig backend_config(const std::string& dialect) {
    interp::BackendConfig backend;
    backend.optional_stop = true;  // M01 reaches motion, which obeys motion.optional-stop
    // As `cnc canon --dialect ncstudio-v54`: V5.4's M10/M11 clamp, M902 sets 0, M06 changes.
    backend.v54_compat = dialect == "ncstudio-v54";
    backend.t_changes_tool = !backend.v54_compat;
    return backend;
}

}  // namespace machine_program
