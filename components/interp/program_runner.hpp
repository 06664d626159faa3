// The interp component's non-realtime side: a thread that runs the interpreter library on a
// program and writes its canonical commands, encoded (interp/canon_wire.hpp), into a channel
// (the HAL stream). Queue-busting reads (#CURMACHPOS, #CURWORKPOS, G906) wait until the
// consumer has followed everything sent so far and stands in position, then read the
// machine's live position. HAL-free: interp.cpp adapts it to pins and a stream.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "../machine_program.hpp"
#include "hal/worker.hpp"
#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"

namespace interp {
class Interpreter;
}  // namespace interp

namespace machine_program {
class MachineExecutor;
}  // namespace machine_program

namespace interpcomp {

// The far side of the stream, as the runner's thread sees it. Every call is non-blocking.
class MachineLink {
  public:
    virtual ~MachineLink() = default;
    // Appends a record to the stream; false when it is full.
    virtual bool push(const interp::wire::Record& r) noexcept = 0;
    // Barriers (Sync records) the consumer has reached with the machine in position.
    virtual std::uint32_t barriers_reached() const noexcept = 0;
    // Live machine state, valid when a barrier was just reached: the position (mm, degrees for
    // A B C), the digital inputs and outputs (bit n = port n), the spindle speed (rpm), and
    // whether the last conditional move (G904) stopped because its inputs came.
    virtual double machine_pos_mm(int axis) const noexcept = 0;
    virtual std::uint64_t input_bits() const noexcept = 0;
    virtual std::uint64_t output_bits() const noexcept = 0;
    virtual double spindle_rpm() const noexcept = 0;
    virtual bool probe_tripped() const noexcept = 0;
    // Where the last G904's input came on axis 0..2 (X Y Z), machine coordinates; the live
    // position where the machine tells nothing else.
    virtual double probe_pos_mm(int axis) const noexcept { return machine_pos_mm(axis); }
    // Polled by the runner's thread: true gives the rest of the program up.
    virtual bool abort_requested() const noexcept { return false; }
    // Called by the runner's thread whenever its status (line, waiting, done, failed) may have
    // changed, so an adapter can publish it.
    virtual void on_progress() noexcept {}
};

struct RunnerConfig {
    std::string program_path;
    // Dialect, the machine's [RS274NGC] settings, its state files and what they held.
    machine_program::Options options;
    bool standalone = false;  // no machine: answer reads from the interpreter's own model
};

class ProgramRunner {
  public:
    ProgramRunner(RunnerConfig cfg, MachineLink& link);
    ~ProgramRunner();
    ProgramRunner(const ProgramRunner&) = delete;
    ProgramRunner& operator=(const ProgramRunner&) = delete;

    // Configuration world. Starts (or resumes) the thread and blocks until the whole program
    // is in the stream, the stream is full, the runner waits for the machine at a barrier, or
    // the program failed. Returns true if it had failed by then.
    bool start_and_wait_ready();
    // Configuration world: pauses (joins the thread). A runner waiting at a barrier gives the
    // rest of the program up (it cannot pause inside a block).
    void stop();
    // Gives the rest of the program up: an end record with "aborted" follows what was sent.
    void abort() noexcept { abort_.store(true, std::memory_order_relaxed); }

    // Any thread.
    bool done() const noexcept { return done_.load(std::memory_order_acquire); }
    bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }
    bool waiting() const noexcept { return waiting_.load(std::memory_order_relaxed); }
    bool running() const noexcept { return running_.load(std::memory_order_relaxed); }
    int line() const noexcept { return line_.load(std::memory_order_relaxed); }
    std::uint32_t barriers_sent() const noexcept {
        return barriers_.load(std::memory_order_relaxed);
    }
    // "file:line:col: reason", once failed() is true.
    std::string error() const;
    // Configuration world, while stopped: the end record (with any error) is in the stream.
    bool end_sent() const noexcept { return finished_ && outbox_.empty(); }

    // Used by the runner's sink and machine query, on the runner's thread.
    void send(const interp::Canon& c);
    // Sends a barrier at `loc` and waits until the machine has reached it in position.
    void sync(const interp::SourceLoc& loc);
    // True when nothing was sent since the last barrier was reached: the machine is current.
    bool machine_current() const noexcept { return current_; }
    // After a conditional move (G904) was sent: waits until the machine has made it, then the
    // interpreter's model takes the point where its inputs came; a move whose inputs never
    // came is an error at `loc` (NCX-3's alarm). See ../probe_result.hpp.
    void adopt_probe_result(const interp::SourceLoc& loc, const interp::canon::ConditionalMove& cm);

  private:
    class Sink;
    class LiveMachine;
    struct Stopped {};  // unwinds a barrier wait when the runner is stopped or aborted

    void run() noexcept;
    void open_program();
    bool deliver() noexcept;  // outbox -> stream as far as it fits; true when all went
    // `error` whole ("" = the program completed); with a place, the end record carries the
    // place and the cause apart, so the consumer can name the line without parsing the text.
    void finish(const std::string& error, const interp::SourceLoc* place = nullptr,
                std::string_view cause = {});
    void fail_with(const interp::Error& e);
    void give_up(std::string_view why);
    void mark_ready();
    bool stopping() noexcept;

    RunnerConfig cfg_;
    MachineLink& link_;
    interp::wire::Encoder encoder_;
    std::unique_ptr<Sink> sink_;
    std::unique_ptr<machine_program::MachineExecutor> backend_;  // saves settings changes
    std::unique_ptr<LiveMachine> machine_;
    std::unique_ptr<interp::Interpreter> interpreter_;
    std::deque<interp::wire::Record> outbox_;
    std::vector<interp::wire::Record> scratch_;
    interp::SourceLoc last_loc_;
    bool finished_ = false;  // the end record is in the outbox
    bool current_ = false;

    std::atomic<bool> abort_{false};
    std::atomic<bool> done_{false};
    std::atomic<bool> failed_{false};
    std::atomic<bool> waiting_{false};
    std::atomic<bool> running_{false};
    std::atomic<int> line_{0};
    std::atomic<std::uint32_t> barriers_{0};

    mutable std::mutex mutex_;
    std::string error_;
    hal::Worker worker_;  // last: joins the thread before the state it uses goes
};

}  // namespace interpcomp
