#pragma once
// Shared by the fuzz targets: a MachineQuery answering fixed values, and an executor that
// accepts everything. Errors (interp::Error) are the expected outcome of bad input; anything
// else escaping — another exception, a crash, a sanitizer report — is a bug.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "interp/block.hpp"
#include "interp/interpreter.hpp"

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

// Opens the input as a program and steps it, as `cnc check` does: an error in one block is
// reported and stepping goes on. The step cap keeps loops (M99, G65 L) from running forever.
inline void run_input(Interpreter& in, const std::uint8_t* data, std::size_t size) {
    constexpr int kMaxSteps = 2000;
    in.open(Source::from_string("fuzz.nc", std::string(reinterpret_cast<const char*>(data), size)));
    for (int steps = 0; steps < kMaxSteps; ++steps) {
        try {
            if (!in.step()) break;
        } catch (const Error&) {
        }
    }
}

}  // namespace interp::fuzz
