// What the interpreter remembers between runs on a machine (machine_program::StateFiles: the
// settings file and the tool table): read with the machine's options, before anything runs, and
// written back atomically as soon as a block has changed it, so a run that is stopped, aborted
// or crashes afterwards keeps it; locked for the run (StateLocks), so that a second run on the
// same files is refused instead of overwriting the first one's changes. One implementation for
// both ways a machine runs programs: the interp component's runner and motion's own program
// feeder (program=). Configuration world: the interpreter's thread.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "interp/block.hpp"
#include "interp/executor.hpp"
#include "interp/persist.hpp"
#include "interp/tooltable.hpp"
#include "machine_program.hpp"

namespace machine_program {

namespace state_detail {

// A path that cannot be looked at (no permission, …) counts as there: its load says why.
inline bool present(const std::string& path) {
    std::error_code ec;
    return std::filesystem::status(path, ec).type() != std::filesystem::file_type::not_found;
}

// The file to read for `file`: itself once it exists, else its seed, else none ("").
inline std::string source_of(const std::string& file, const std::string& seed) {
    if (file.empty()) return "";
    if (present(file)) return file;
    if (!seed.empty() && present(seed)) return seed;
    return "";
}

}  // namespace state_detail

// The settings of `files`, with the tool table's tools in place of any the settings file lists.
// Missing files give the defaults. Throws interp::Error "file:line:col: cause" for a bad line
// ("file:0:0: cause" for a file that cannot be read).
inline interp::Settings load_state(const StateFiles& files) {
    interp::Settings s;
    if (const std::string src = state_detail::source_of(files.settings, files.settings_seed);
        !src.empty())
        s = interp::load_settings(src);
    if (const std::string src = state_detail::source_of(files.tool_table, files.tool_table_seed);
        !src.empty()) {
        std::error_code ec;
        if (std::filesystem::is_directory(src, ec))
            throw interp::Error(interp::SourceLoc{src, 0, 0},
                                "tool table: cannot read file: Is a directory");
        const interp::ToolTable table = interp::load_linuxcnc_tool_table(src);
        for (const auto& [n, e] : table.entries()) s.tools.at(n) = e;
    }
    return s;
}

// Writes the parts of the settings that changed since the last write (or the load): the tool
// table when it is kept, the rest into the settings file (the tools too when no tool table is).
// Both are edited in place, so what a person wrote in them stays but for the changed values
// (interp::update_linuxcnc_tool_table, interp::update_settings_text).
class StateSaver {
  public:
    StateSaver(StateFiles files, interp::Settings loaded)
        : files_(std::move(files)), saved_(std::move(loaded)) {}

    // Throws std::runtime_error "path: cannot …: cause"; that file keeps its old contents and
    // the next save tries it again.
    void save(const interp::Settings& s) {
        const bool table = !files_.tool_table.empty();
        if (table && !(s.tools == saved_.tools)) {
            interp::save_tool_table_atomic(files_.tool_table, s.tools, files_.tool_table_seed);
            saved_.tools = s.tools;
        }
        if (files_.settings.empty()) return;
        const bool tools_here = !table;
        if (s.offsets == saved_.offsets && s.params == saved_.params &&
            (!tools_here || s.tools == saved_.tools))
            return;
        if (tools_here) {
            interp::save_settings_atomic(files_.settings, s, files_.settings_seed);
        } else {
            interp::Settings rest;
            rest.offsets = s.offsets;
            rest.params = s.params;
            interp::save_settings_atomic(files_.settings, rest, files_.settings_seed);
        }
        saved_.offsets = s.offsets;
        saved_.params = s.params;
        if (tools_here) saved_.tools = s.tools;
    }

  private:
    StateFiles files_;
    interp::Settings saved_;  // what the files hold now
};

// The locks on a machine's settings file and tool table (interp::SettingsFileLock), held by
// whoever may save them for as long as it may. Throws std::runtime_error naming the file (and
// the holder's process id) when another run holds one.
class StateLocks {
  public:
    explicit StateLocks(const StateFiles& files) {
        for (const std::string* path : {&files.settings, &files.tool_table})
            if (!path->empty()) locks_.push_back(std::make_unique<interp::SettingsFileLock>(*path));
    }

  private:
    std::vector<std::unique_ptr<interp::SettingsFileLock>> locks_;
};

// The back end a machine runs programs with: an interp::Executor started from the options'
// settings, each change saved before the interpreter goes on. A failed save is an error of the
// block that made the change: `prog.ngc:3:1: settings not saved: …`. Give the interpreter this
// object as its BlockExecutor, and executor() as its MachineQuery where it needs one.
class MachineExecutor final : public interp::BlockExecutor {
  public:
    // Throws std::runtime_error when another run holds the settings files (StateLocks).
    MachineExecutor(interp::CanonSink& sink, const Options& o)
        : locks_(o.state), saver_(o.state, o.settings), exec_(sink, backend_config(o), o.settings) {
        exec_.on_settings_changed([this](const interp::Settings& s) { save(s); });
    }
    MachineExecutor(const MachineExecutor&) = delete;
    MachineExecutor& operator=(const MachineExecutor&) = delete;

    void execute(const interp::Block& b) override {
        at_ = b.loc;
        exec_.execute(b);
    }
    void end_of_input(const interp::SourceLoc& loc) override {
        at_ = loc;
        exec_.end_of_input(loc);
    }
    interp::Executor& executor() noexcept { return exec_; }

  private:
    // Also reached from a persistent parameter the front end writes after its block executed
    // (#FIXEDCALI_REC), so `at_` is still that block.
    void save(const interp::Settings& s) {
        try {
            saver_.save(s);
        } catch (const std::runtime_error& e) {
            throw interp::Error(
                at_,
                fmt::format("settings not saved: {} (the file keeps its old contents)", e.what()));
        }
    }

    StateLocks locks_;  // first in, last out: held while anything here may save
    StateSaver saver_;
    interp::Executor exec_;
    interp::SourceLoc at_;  // the block being executed
};

// What named parameters read on a machine: the executor's model for everything, so that a
// program path overrides only what its machine knows better (positions, I/O, the spindle).
// Work positions follow the machine position with the interpreter's offsets (work = machine
// - offsets), whoever answers the machine position.
class ModelQuery : public interp::MachineQuery {
  public:
    explicit ModelQuery(interp::Executor& exec) : exec_(exec) {}

    double machine_pos_mm(interp::Axis axis) override { return exec_.machine_pos_mm(axis); }
    double work_pos_mm(interp::Axis axis) override {
        return exec_.work_pos_mm(axis) + machine_pos_mm(axis) - exec_.machine_pos_mm(axis);
    }
    std::uint64_t input_bits() override { return exec_.input_bits(); }
    std::uint64_t output_bits() override { return exec_.output_bits(); }
    double spindle_rpm() override { return exec_.spindle_rpm(); }
    double mm_per_program_unit() override { return exec_.mm_per_program_unit(); }
    bool incremental_mode() override { return exec_.incremental_mode(); }
    bool cycle_return_to_r() override { return exec_.cycle_return_to_r(); }
    std::optional<double> setting(std::string_view name) override { return exec_.setting(name); }
    // Writable named parameters (#FIXEDCALI_REC) persist in the executor's settings.
    bool can_write_setting(std::string_view name) override { return exec_.can_write_setting(name); }
    void write_setting(std::string_view name, double value) override {
        exec_.write_setting(name, value);
    }

  protected:
    interp::Executor& exec_;
};

}  // namespace machine_program
