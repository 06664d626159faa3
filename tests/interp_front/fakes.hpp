#pragma once
// Test doubles for the two interfaces the front end talks to.
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "interp/block.hpp"

namespace interp::test {

// Answers from plain fields the test sets.
class FakeMachine : public MachineQuery {
  public:
    std::array<double, kMachineAxes> machine_mm{};
    std::array<double, kMachineAxes> work_mm{};
    std::uint64_t inputs = 0;
    std::uint64_t outputs = 0;
    double rpm = 0.0;
    double mm_per_unit = 1.0;
    bool incremental = false;
    bool return_to_r = false;
    std::map<std::string, double, std::less<>> settings;
    bool keeps_settings = false;                        // can_write_setting() answer
    std::vector<std::pair<std::string, double>> writes;  // write_setting() calls, in order

    double machine_pos_mm(Axis a) override { return machine_mm[static_cast<int>(a)]; }
    double work_pos_mm(Axis a) override { return work_mm[static_cast<int>(a)]; }
    std::uint64_t input_bits() override { return inputs; }
    std::uint64_t output_bits() override { return outputs; }
    double spindle_rpm() override { return rpm; }
    double mm_per_program_unit() override { return mm_per_unit; }
    bool incremental_mode() override { return incremental; }
    bool cycle_return_to_r() override { return return_to_r; }
    std::optional<double> setting(std::string_view name) override {
        auto it = settings.find(name);
        if (it == settings.end()) return std::nullopt;
        return it->second;
    }
    bool can_write_setting(std::string_view) override { return keeps_settings; }
    void write_setting(std::string_view name, double v) override {
        writes.emplace_back(std::string(name), v);
        settings[std::string(name)] = v;
    }
};

// Records every executed block; can be told to reject a block at a given line.
class RecordingExecutor : public BlockExecutor {
  public:
    std::vector<Block> blocks;
    std::vector<SourceLoc> ends;
    int reject_line = -1;

    void execute(const Block& b) override {
        if (b.loc.line == reject_line) throw Error(b.loc, "rejected by test executor");
        blocks.push_back(b);
    }
    void end_of_input(const SourceLoc& loc) override { ends.push_back(loc); }

    // "file:line" of each executed block, for sequence checks.
    std::vector<int> lines() const {
        std::vector<int> out;
        for (const Block& b : blocks) out.push_back(b.loc.line);
        return out;
    }
    // The value of `letter` in each executed block that has it.
    std::vector<double> values(char letter) const {
        std::vector<double> out;
        for (const Block& b : blocks)
            if (b.has(letter)) out.push_back(b.get(letter));
        return out;
    }
};

}  // namespace interp::test
