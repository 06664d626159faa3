// `cnc`: the command-line front door of the interpreter.
//   cnc canon PROGRAM   print the canonical command stream (native or LinuxCNC rs274 -g form)
//   cnc check PROGRAM   run the whole program without motion; every error as file:line:col,
//                       then a summary (extents, tools, path length)
//   cnc run INI PROGRAM run the program on a machine config (run.cpp)
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "interp/canon_print.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/persist.hpp"
#include "interp/tooltable.hpp"
#include "run.hpp"

namespace {

struct CommonOptions {
    std::string program;
    std::string dialect = "ncstudio";
    std::string tool_table;
    std::string library;
    std::string settings;
    bool save_settings = false;
    bool optional_stop = false;
    bool no_g00_split = false;
    bool use_default_speed = false;
    double default_feed_mm_min = 0;
    std::vector<std::string> g904_trips;
};

void add_common(CLI::App& cmd, CommonOptions& o) {
    cmd.add_option("PROGRAM", o.program, "G-code program")->required()->check(CLI::ExistingFile);
    cmd.add_option("--dialect", o.dialect,
                   "ncstudio (6th edition), ncstudio-v54 or another dialect the front end knows")
        ->check(CLI::Validator(
            [](std::string& name) {
                return interp::find_dialect(name) ? std::string{}
                                                  : "unknown dialect '" + name + "'";
            },
            "DIALECT"));
    cmd.add_option("-t,--tool-table", o.tool_table, "LinuxCNC tool table (.tbl)")
        ->check(CLI::ExistingFile);
    cmd.add_option("-l,--library", o.library, "public.dat subprogram library")
        ->check(CLI::ExistingFile);
    cmd.add_option("--settings", o.settings,
                   "persistent settings file (work offsets, G92, tools, parameters)");
    cmd.add_flag("--optional-stop", o.optional_stop, "M01 stops (the operator's switch is on)");
    cmd.add_option("--default-feed", o.default_feed_mm_min,
                   "machine default feed (mm/min) for feed moves before any F; 0 = error")
        ->check(CLI::NonNegativeNumber);
    cmd.add_flag("--use-default-speed", o.use_default_speed,
                 "NcStudio \"use default speed\": moves run at --default-feed and the machine's "
                 "rapid speed whatever F says; only G905 blocks use the programmed F");
    cmd.add_option("--g904-trip", o.g904_trips,
                   "AXIS=MM: machine coordinate where a G904 input changes (simulation)");
    cmd.add_flag("--no-g00-split", o.no_g00_split,
                 "G00 as one straight move (NcStudio splits Z first/last)");
}

// Everything a run needs, built from the options; throws interp::Error / runtime_error.
struct Session {
    interp::Settings settings;
    interp::BackendConfig cfg;
    interp::InterpreterOptions iopts;
};

Session make_session(const CommonOptions& o) {
    Session s;
    if (!o.settings.empty()) s.settings = interp::load_settings(o.settings);
    if (!o.tool_table.empty()) {
        const interp::ToolTable t = interp::load_linuxcnc_tool_table(o.tool_table);
        for (const auto& [n, e] : t.entries()) s.settings.tools.at(n) = e;
    }
    s.cfg.v54_compat = o.dialect == "ncstudio-v54";
    s.cfg.t_changes_tool = !s.cfg.v54_compat;  // C-29: V5.4 changes the tool at M06
    s.cfg.optional_stop = o.optional_stop;
    s.cfg.g00_z_split = !o.no_g00_split;
    s.cfg.default_feed_mm_s = o.default_feed_mm_min / 60.0;
    s.cfg.use_default_speed = o.use_default_speed;
    if (o.use_default_speed && o.default_feed_mm_min <= 0)
        throw std::runtime_error("--use-default-speed needs --default-feed MM_PER_MIN");
    s.iopts.dialect = interp::find_dialect(o.dialect);
    for (const std::string& t : o.g904_trips) {
        const auto eq = t.find('=');
        const std::string axis = t.substr(0, eq);
        if (eq == std::string::npos || axis.size() != 1 || axis[0] < 'X' || axis[0] > 'Z')
            throw std::runtime_error("--g904-trip " + t + ": expected X=mm, Y=mm or Z=mm");
        s.cfg.g904_trip_mm[axis[0] - 'X'] = std::stod(t.substr(eq + 1));
    }
    return s;
}

void attach_saver(interp::Executor& exec, const CommonOptions& o) {
    if (o.settings.empty() || !o.save_settings) return;
    exec.on_settings_changed(
        [path = o.settings](const interp::Settings& s) { interp::save_settings_atomic(path, s); });
}

int run_canon(const CommonOptions& o, const std::string& format, const std::string& out_path) {
    // Taken before the settings are read, so a `cnc run` on the same file cannot change them
    // between our read and our saves (the last save would win).
    std::optional<interp::SettingsFileLock> settings_lock;
    if (!o.settings.empty() && o.save_settings) settings_lock.emplace(o.settings);
    Session s = make_session(o);
    std::FILE* out = stdout;
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(nullptr, &std::fclose);
    if (!out_path.empty()) {
        file.reset(std::fopen(out_path.c_str(), "w"));
        if (!file) throw std::runtime_error(out_path + ": cannot open for writing");
        out = file.get();
    }
    interp::NativePrinter native(out);
    interp::LinuxCncPrinter lcnc(out);
    interp::CanonSink& printer = format == "linuxcnc" ? static_cast<interp::CanonSink&>(lcnc)
                                                      : static_cast<interp::CanonSink&>(native);
    // Warnings also go to stderr as file:line:col, like errors, without failing the run.
    interp::WarningPrinter warnings(stderr);
    interp::TeeSink sink;
    sink.add(printer);
    sink.add(warnings);
    s.iopts.warnings = &warnings;
    interp::Executor exec(sink, s.cfg, s.settings);
    attach_saver(exec, o);
    interp::Interpreter in(exec, exec, s.iopts);
    if (!o.library.empty()) in.load_library(o.library);
    in.open(o.program);
    int status = 0;
    try {
        in.run();
    } catch (const interp::Error& e) {
        std::fflush(out);
        fmt::print(stderr, "{}\n", e.what());
        status = 1;
    }
    if (format == "linuxcnc") lcnc.finish();
    return status;
}

std::string range(double lo, double hi) {
    return fmt::format("{} .. {}", interp::fmt_num(lo), interp::fmt_num(hi));
}

int run_check(const CommonOptions& o, int max_errors) {
    Session s = make_session(o);
    s.iopts.main_m99_loops = false;  // a checker must terminate
    interp::SummarySink summary;
    interp::WarningPrinter warnings(stderr);
    interp::TeeSink sink;
    sink.add(summary);
    sink.add(warnings);
    s.iopts.warnings = &warnings;
    interp::Executor exec(sink, s.cfg, s.settings);  // check never writes settings
    interp::Interpreter in(exec, exec, s.iopts);
    if (!o.library.empty()) in.load_library(o.library);
    in.open(o.program);
    int errors = 0;
    for (;;) {
        try {
            if (!in.step()) break;
        } catch (const interp::Error& e) {
            fmt::print(stderr, "{}\n", e.what());
            if (++errors >= max_errors) {
                fmt::print(stderr, "{}: too many errors, stopping\n", o.program);
                break;
            }
        }
    }
    const int warned = warnings.count();
    fmt::print("{}: {} error{}{}\n", o.program, errors, errors == 1 ? "" : "s",
               warned == 0 ? "" : fmt::format(", {} warning{}", warned, warned == 1 ? "" : "s"));
    if (summary.any_motion()) {
        const auto lo = summary.min_mm(), hi = summary.max_mm();
        fmt::print("extents (machine, mm): X {}  Y {}  Z {}\n", range(lo[0], hi[0]),
                   range(lo[1], hi[1]), range(lo[2], hi[2]));
    } else {
        fmt::print("extents (machine, mm): no motion\n");
    }
    std::string tools;
    for (int t : summary.tools()) tools += fmt::format(" T{}", t);
    fmt::print("tools used:{}\n", tools.empty() ? " none" : tools);
    fmt::print("moves: {}  feed length: {} mm  rapid length: {} mm  total: {} mm\n",
               summary.moves(), interp::fmt_num(summary.feed_length_mm()),
               interp::fmt_num(summary.rapid_length_mm()),
               interp::fmt_num(summary.feed_length_mm() + summary.rapid_length_mm()));
    const long secs = std::lround(summary.feed_time_s());
    fmt::print(
        "estimated feed time: {}:{:02d}:{:02d} (feed moves and dwells at 100 %, rapids "
        "not included)\n",
        secs / 3600, (secs / 60) % 60, secs % 60);
    return errors == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"cnc: G-code interpreter tools"};
    app.require_subcommand(1);

    CommonOptions canon_opts;
    std::string format = "native";
    std::string out_path;
    CLI::App* canon = app.add_subcommand("canon", "print the canonical command stream");
    add_common(*canon, canon_opts);
    canon->add_option("--format", format, "native or linuxcnc (LinuxCNC rs274 -g style)")
        ->check(CLI::IsMember({"native", "linuxcnc"}));
    canon->add_option("-o,--output", out_path, "write to this file instead of stdout");
    canon->add_flag("--save-settings", canon_opts.save_settings,
                    "write changed offsets/tools back to --settings (atomically)");

    CommonOptions check_opts;
    int max_errors = 100;
    CLI::App* check = app.add_subcommand("check", "run the program without motion, report errors");
    add_common(*check, check_opts);
    check->add_option("--max-errors", max_errors, "stop after this many errors")
        ->check(CLI::PositiveNumber);

    cncrun::RunOptions run_opts;
    CLI::App* run = cncrun::add_run_command(app, run_opts);

    CLI11_PARSE(app, argc, argv);
    if (run->parsed()) return cncrun::run_program(run_opts);
    try {
        if (canon->parsed()) return run_canon(canon_opts, format, out_path);
        return run_check(check_opts, max_errors);
    } catch (const std::exception& e) {
        // Setup errors (settings file, tool table, program file): nothing has run.
        fmt::print(stderr, "{}\n", e.what());
        return 2;
    }
}
