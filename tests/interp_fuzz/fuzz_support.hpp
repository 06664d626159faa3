#pragma once
// Shared by the fuzz targets: a MachineQuery answering fixed values, and an executor that
// accepts everything. Errors (interp::Error) are the expected outcome of bad input; anything
// else escaping — another exception, a crash, a sanitizer report — is a bug.
#include <cstdint>
#include <optional>
#include <string_view>

#include "interp/block.hpp"

namespace interp::fuzz {

class FixedMachine : public MachineQuery {
  public:
    double machine_pos_mm(Axis a) override { return 10.0 * static_cast<int>(a) + 1.5; }
    double work_pos_mm(Axis a) override { return -5.0 * static_cast<int>(a); }
    std::uint64_t input_bits() override { return 0xA5; }
    std::uint64_t output_bits() override { return 0x3C; }
    double spindle_rpm() override { return 12000.0; }
    double mm_per_program_unit() override { return 1.0; }
    bool incremental_mode() override { return false; }
    bool cycle_return_to_r() override { return true; }
    std::optional<double> setting(std::string_view name) override {
        // Leave one setting unconfigured so the "not configured" path is reachable too.
        if (name == "SAFEHEIGHT") return std::nullopt;
        return static_cast<double>(name.size());
    }
};

class AcceptingExecutor : public BlockExecutor {
  public:
    std::uint64_t blocks = 0;
    void execute(const Block&) override { ++blocks; }
    void end_of_input(const SourceLoc&) override {}
};

}  // namespace interp::fuzz
