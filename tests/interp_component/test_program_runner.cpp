// The interp component's runner (components/interp/program_runner.cpp) against a fake machine
// that decodes what is sent: a queue-busting read sends a barrier and waits until the machine
// says it reached it, then reads the live position; without a machine (standalone) it reads
// the model; an abort while waiting gives the program up with file:line:col.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"
#include "program_runner.hpp"

namespace {

namespace fs = std::filesystem;
using interpcomp::ProgramRunner;
using interpcomp::RunnerConfig;

// Decodes every record into text lines; the test decides when a barrier counts as reached.
class FakeMachine : public interpcomp::MachineLink {
  public:
    bool push(const interp::wire::Record& r) noexcept override {
        std::lock_guard lock(mutex_);
        if (capacity_ == 0) return false;
        --capacity_;
        try {
            switch (decoder_.feed(r)) {
                case interp::wire::Decoder::Item::Command: {
                    const interp::Canon& c = decoder_.command();
                    lines_.push_back(interp::to_text(c));
                    if (std::holds_alternative<interp::canon::Sync>(c.cmd)) ++barriers_sent_;
                    break;
                }
                case interp::wire::Decoder::Item::End:
                    lines_.push_back(decoder_.failed() ? "end failed: " + decoder_.error() : "end");
                    if (const auto& at = decoder_.error_loc())
                        end_place_ = fmt::format("{}:{} {}", at->line, at->col,
                                                 decoder_.error_cause());
                    break;
                case interp::wire::Decoder::Item::None:
                    break;
            }
        } catch (const std::exception& e) {
            lines_.push_back(std::string("bad record: ") + e.what());
        }
        return true;
    }
    std::uint32_t barriers_reached() const noexcept override { return reached_.load(); }
    double machine_pos_mm(int axis) const noexcept override {
        return axis == 0 ? 7.5 : axis == 2 ? z_mm_.load() : 0.0;
    }
    std::uint64_t input_bits() const noexcept override { return 0b101; }
    std::uint64_t output_bits() const noexcept override { return 0; }
    double spindle_rpm() const noexcept override { return 1234; }
    bool probe_tripped() const noexcept override { return tripped_.load(); }
    bool abort_requested() const noexcept override { return abort_.load(); }

    void reach_barriers() { reached_.store(barriers_sent()); }
    std::uint32_t barriers_sent() const {
        std::lock_guard lock(mutex_);
        return barriers_sent_;
    }
    std::vector<std::string> lines() const {
        std::lock_guard lock(mutex_);
        return lines_;
    }
    // "line:col cause" of an end record that carries its place apart, else empty.
    std::string end_place() const {
        std::lock_guard lock(mutex_);
        return end_place_;
    }
    std::atomic<bool> abort_{false};
    std::atomic<double> z_mm_{0};
    std::atomic<bool> tripped_{true};

  private:
    mutable std::mutex mutex_;
    interp::wire::Decoder decoder_;
    std::vector<std::string> lines_;
    std::string end_place_;
    std::uint32_t barriers_sent_ = 0;
    std::size_t capacity_ = 1'000'000;
    std::atomic<std::uint32_t> reached_{0};
};

class Program {
  public:
    explicit Program(const std::string& text)
        : path_(fs::temp_directory_path() / ("runner_test_" + std::to_string(::getpid()) + "_" +
                                             std::to_string(next_++) + ".ngc")) {
        std::ofstream(path_) << text;
    }
    ~Program() { fs::remove(path_); }
    std::string path() const { return path_.string(); }

  private:
    static inline int next_ = 0;
    fs::path path_;
};

bool eventually(const std::function<bool()>& cond) {
    for (int i = 0; i < 2000; ++i) {
        if (cond()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return cond();
}

constexpr const char* kRead = "G90 G21\nG1 X10 F600\n#1 = #CURMACHPOS.X\nG1 Y=#1\nM30\n";

TEST(ProgramRunner, ReadWaitsAtABarrierThenUsesTheLivePosition) {
    Program prog(kRead);
    FakeMachine machine;
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    // start returned because the runner waits for the machine: line 2's move and a barrier
    // were sent, nothing after them.
    EXPECT_TRUE(eventually([&] { return runner.waiting(); }));
    EXPECT_EQ(machine.barriers_sent(), 1u);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(runner.done());
    auto lines = machine.lines();
    ASSERT_GE(lines.size(), 2u);
    EXPECT_EQ(lines.back(), "2 sync");
    machine.reach_barriers();
    ASSERT_TRUE(eventually([&] { return runner.done(); }));
    runner.stop();
    lines = machine.lines();
    // The Y move goes to the machine's X (7.5 from the fake machine), not the model's 10.
    bool y_from_machine = false;
    for (const auto& l : lines)
        y_from_machine =
            y_from_machine || (l.rfind("4 feed ", 0) == 0 && l.find("Y7.5") != std::string::npos);
    EXPECT_TRUE(y_from_machine) << ::testing::PrintToString(lines);
    EXPECT_EQ(lines.back(), "end");
    EXPECT_FALSE(runner.failed());
}

TEST(ProgramRunner, StandaloneReadsTheModelWithoutWaiting) {
    Program prog(kRead);
    FakeMachine machine;
    ProgramRunner runner(RunnerConfig{prog.path(), {}, true}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    ASSERT_TRUE(eventually([&] { return runner.done(); }));
    runner.stop();
    bool y_from_model = false;
    for (const auto& l : machine.lines())
        y_from_model =
            y_from_model || (l.rfind("4 feed ", 0) == 0 && l.find("Y10") != std::string::npos);
    EXPECT_TRUE(y_from_model) << ::testing::PrintToString(machine.lines());
}

TEST(ProgramRunner, AbortWhileWaitingGivesTheProgramUpWithItsLocation) {
    Program prog(kRead);
    FakeMachine machine;
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    ASSERT_TRUE(eventually([&] { return runner.waiting(); }));
    machine.abort_.store(true);
    ASSERT_TRUE(eventually([&] { return runner.failed(); }));
    runner.stop();
    EXPECT_EQ(runner.error(), prog.path() +
                                  ":2:1: aborted while waiting for the machine; the rest of the "
                                  "program is given up");
    const auto lines = machine.lines();
    EXPECT_EQ(lines.back(), "end failed: " + runner.error());
    EXPECT_EQ(machine.end_place(),
              "2:1 aborted while waiting for the machine; the rest of the program is given up");
}

TEST(ProgramRunner, ASyntaxErrorFailsBeforeStartReturns) {
    Program prog("G90 G21\nG1 X10 F600\nG1 X20 Q\nM30\n");
    FakeMachine machine;
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_TRUE(runner.start_and_wait_ready());
    EXPECT_EQ(runner.error(), prog.path() + ":3:8: expected a number or '=' after Q");
    EXPECT_EQ(machine.end_place(), "3:8 expected a number or '=' after Q");
    const auto lines = machine.lines();
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(lines.back(), "end failed: " + runner.error());
    // Line 2's move went out before the error: the machine runs out what came before it.
    bool line2 = false;
    for (const auto& l : lines) line2 = line2 || l.rfind("2 feed ", 0) == 0;
    EXPECT_TRUE(line2);
}

// Reads of the ports and the spindle wait at a barrier like position reads, then take the
// machine's values (inputs 0 and 2 on, 1234 rpm), not the model's (no inputs, 0 rpm).
TEST(ProgramRunner, PortAndSpindleReadsComeFromTheMachine) {
    Program prog("G90 G21\nG1 X1 F600\n#1 = #IMPORTMAP\nG1 X=#1\nM30\n");
    FakeMachine machine;
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    ASSERT_TRUE(eventually([&] { return runner.waiting(); }));
    machine.reach_barriers();
    ASSERT_TRUE(eventually([&] { return runner.done(); })) << runner.error();
    runner.stop();
    bool x_from_machine = false;
    for (const auto& l : machine.lines())
        x_from_machine =
            x_from_machine || (l.rfind("4 feed ", 0) == 0 && l.find("X5") != std::string::npos);
    EXPECT_TRUE(x_from_machine) << ::testing::PrintToString(machine.lines());
}

// After a G904 the runner waits until the machine has made it, then its model starts from where
// Z stopped: the incremental Z5 after it ends 5 mm above the machine's -3.25.
TEST(ProgramRunner, ConditionalMoveContinuesFromWhereTheMachineStopped) {
    Program prog("G90 G21\nG904 FZ-600 PZ1 LZ1 Z20\nG91 G0 Z5\nM30\n");
    FakeMachine machine;
    machine.z_mm_.store(-3.25);
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    ASSERT_TRUE(eventually([&] { return runner.waiting(); }));
    EXPECT_EQ(machine.lines().back(), "2 sync");
    machine.reach_barriers();
    ASSERT_TRUE(eventually([&] { return runner.done(); })) << runner.error();
    runner.stop();
    bool z_from_stop = false;
    for (const auto& l : machine.lines())
        z_from_stop =
            z_from_stop || (l.rfind("3 traverse ", 0) == 0 && l.find("Z1.75") != std::string::npos);
    EXPECT_TRUE(z_from_stop) << ::testing::PrintToString(machine.lines());
}

// A G904 that ended without its input (probe-tripped FALSE) is an error at its location.
TEST(ProgramRunner, ConditionalMoveWithoutItsInputFailsAtItsLine) {
    Program prog("G90 G21\nG904 FZ-600 PZ1 LZ1 Z20\nG91 G0 Z5\nM30\n");
    FakeMachine machine;
    machine.z_mm_.store(-20);
    machine.tripped_.store(false);
    ProgramRunner runner(RunnerConfig{prog.path(), {}, false}, machine);
    EXPECT_FALSE(runner.start_and_wait_ready());
    ASSERT_TRUE(eventually([&] { return runner.waiting(); }));
    machine.reach_barriers();
    ASSERT_TRUE(eventually([&] { return runner.failed(); }));
    runner.stop();
    EXPECT_EQ(runner.error(), prog.path() +
                                  ":2:1: G904: Z stopped at -20 mm with input 1 not at level 1 "
                                  "(the maximum travel or a soft limit came first)");
    for (const auto& l : machine.lines()) EXPECT_NE(l.rfind("3 ", 0), 0u) << l;
}

}  // namespace
