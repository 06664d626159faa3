// `cnc run INI PROGRAM`: runs a G-code program on a machine config (INI + HAL files) in an
// in-process HAL instance, shows progress and prints a summary. See docs/cnc-run.md.
#pragma once

#include <string>

namespace CLI {
class App;
}

namespace cncrun {

struct RunOptions {
    std::string ini;
    std::string program;
    std::string trace_path;    // empty: no trace
    std::string preview_path;  // empty: no picture
    std::string settings_dir;  // empty: the state files are where the INI says
    bool sim_clock = false;
    bool resume_pauses = false;  // M00/M01/single-block pauses resume at once
    double timeout_s = 3600;     // motion time (simulated under --sim-clock)
};

// Registers the `run` subcommand on `app`, filling `o` when parsed.
CLI::App* add_run_command(CLI::App& app, RunOptions& o);

// Runs the program; returns the process exit status (0 done, 1 error or fault, 130 Ctrl-C).
int run_program(const RunOptions& o);

}  // namespace cncrun
