// The non-realtime side of the motion component: a thread that gets canonical commands (from
// the interpreter run on a program file in-process, or decoded from the `interp` component's
// stream), turns them into planner segments and keeps the realtime ring filled with prepared
// records. HAL-free; motion.cpp owns it.
//
// Barriers (canon::Sync, sent by the interp component for G906 and for queue-busting reads
// such as #CURMACHPOS): the feeder finishes the planner, delivers everything before the barrier
// into the ring and then stands "at the barrier" (idle) until the next record arrives. Once the
// servo side is in position there, acknowledge() returns the barrier's number, which motion
// publishes (motion.canon-sync) and the interp component waits for before it reads the
// machine's position.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "../machine_program.hpp"
#include "hal/worker.hpp"
#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"
#include "motion/planner.hpp"
#include "motion/prepared.hpp"
#include "motion/spsc_ring.hpp"
#include "plan_sink.hpp"

namespace interp {
class Interpreter;
class CanonSink;
class MachineQuery;
}  // namespace interp

namespace machine_program {
class MachineExecutor;
}  // namespace machine_program

namespace motioncomp {

struct FeederConfig {
    std::string program_path;  // run in-process when canon_source is empty
    // Pops the next record of the canonical stream (interp/canon_wire.hpp) into the argument;
    // false when none is waiting. Set: commands come from the stream, not from program_path.
    std::function<bool(interp::wire::Record&)> canon_source;
    machine_program::Options program_options;  // dialect and the machine's [RS274NGC] keys
    motion::PlannerConfig plan;
    std::array<bool, motion::kAxes> axis_present{};  // axes named by coordinates=
    std::string coordinates;                         // for error messages
    double blend_tolerance_mm = 0;
    SinkConfig machine;  // soft limits and I/O counts the sink checks moves and commands against
    // The program's texts for the operator (canon::Message for M801, canon::Warning), as they
    // are planned, on the feeder thread. The n-th Message is message n of
    // PreparedSegment::message, shown when the machine reaches it.
    std::function<void(const interp::Canon&)> on_text;
    // The program's error, on the feeder thread, when planning fails (what was planned still
    // runs out): where (nullopt when no place is known; the file view lives as long as the
    // call) and the cause, without the place. error() has the whole text.
    std::function<void(const std::optional<interp::SourceLoc>&, std::string_view cause)> on_error;
    // On the feeder thread, between the planning steps and, once nothing more is planned (the
    // program ended, failed or was abandoned), about every kLingerPoll until stop(). The thread
    // is the owner's one non-realtime thread that lives from start() to stop(): motion uses it
    // to publish a servo function's fault on motion.messages while the machine is still
    // loaded (the stream has one producer at a time, and this thread is it until joined).
    std::function<void()> on_poll;
};

class ProgramFeeder {
  public:
    // How often on_poll runs once the program is over: the latency of a fault's text on
    // motion.messages after the servo function has noted it.
    static constexpr std::chrono::milliseconds kLingerPoll{1};

    ProgramFeeder(FeederConfig cfg, motion::SpscRing<motion::PreparedSegment>& ring);
    ~ProgramFeeder();
    ProgramFeeder(const ProgramFeeder&) = delete;
    ProgramFeeder& operator=(const ProgramFeeder&) = delete;

    // Configuration world. Starts (or resumes, after stop()) the thread and blocks until the
    // whole program is planned and in the ring, the ring is full, or the program failed. The
    // thread then stays until stop(), also once the program is over (see on_poll). This
    // is what makes a simulated-clock run deterministic: the servo function never sees a
    // half-planned queue unless the program is longer than the ring. Returns true if the
    // program had failed by then (decided at that moment, so the answer does not depend on
    // how far the thread gets before the caller looks).
    bool start_and_wait_ready();
    // Configuration world: pauses planning (joins the thread); start_and_wait_ready() resumes.
    void stop();

    // Realtime-safe: gives the rest of the program up for good (abort).
    void abandon() noexcept { abandoned_.store(true, std::memory_order_relaxed); }
    // Spins until the ring is full or nothing more will come. Not realtime-safe: only for the
    // opt-in lock-step mode of simulated-clock runs (see docs/components/motion.md).
    void wait_for_lead() const noexcept;

    // Realtime-safe status. idle(): nothing more is being planned now (the program is over, or
    // the feeder stands at a barrier); servo thread only, as it remembers which barrier it saw.
    bool idle() const noexcept;
    // Servo thread, once per period after idle(): `in_position` is motion's verdict for this
    // period. Returns the number of barriers the machine has reached in position.
    std::uint32_t acknowledge(bool in_position) noexcept;
    bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }
    std::uint32_t ignored_commands() const noexcept {
        return ignored_.load(std::memory_order_relaxed);
    }
    // Configuration world, valid once failed() is true: "file:line:col: reason".
    std::string error() const;
    // Configuration world: the main program's file, for messages about a record's line
    // (program=, or the first file the canonical stream named).
    std::string program_file() const;

    // Used by the canonical-command sink, on the feeder thread.
    void count_ignored() noexcept { ignored_.fetch_add(1, std::memory_order_relaxed); }
    // Moves the planner's finished records to the outbox, then appends `extra` if given.
    void collect(const motion::PreparedSegment* extra = nullptr);
    // After the planner was finished (motion at rest at pos_mm): collects, changes the
    // synchronised outputs still waiting for a move there, then appends `extra` if given.
    void collect_at_rest(const motion::AxisArray& pos_mm, const motion::PreparedSegment* extra);
    // M901: output `port` goes to `level` when the path starts the move with id
    // `from_move_id` (or the first one after it that makes a record).
    void sync_output(int port, bool level, std::uint32_t from_move_id, std::int32_t line);
    // M801: the message is handed to on_text now and falls due, like an M901 output, when the
    // path starts the move `from_move_id` (or comes to rest before it).
    void sync_message(const interp::Canon& message, std::uint32_t from_move_id);
    // A warning for the operator: handed to on_text now.
    void post_text(const interp::Canon& text);
    // A conditional move (G904) was queued: nothing after it is planned until report_probe().
    void await_probe(const interp::SourceLoc& loc, const interp::canon::ConditionalMove& cm);

    // Servo thread, realtime-safe: the conditional move ended at pos_mm, its inputs came at
    // trip_mm (ProbeJog::trip_mm); tripped = every watched input reached its level.
    void report_probe(const motion::AxisArray& pos_mm, const motion::AxisArray& trip_mm,
                      bool tripped) noexcept;

  private:
    enum class Progress { More, Starved, End };
    void run() noexcept;
    void linger() noexcept;
    void poll_owner() noexcept;
    void open_program();
    Progress step();
    Progress read_stream();
    void reach_barrier_if_delivered();
    void leave_barrier() noexcept;
    bool probe_result_waiting() const noexcept;
    void take_probe_result();
    bool stopping() const noexcept;
    void deliver() noexcept;  // outbox -> ring, as far as it fits
    void fail(const std::exception& e);
    void mark_ready();
    void remember_stream_file(std::string_view file);

    FeederConfig cfg_;
    motion::SpscRing<motion::PreparedSegment>& ring_;

    // Planning state: kept across stop()/start so a paused program continues where it was.
    std::unique_ptr<motion::Planner> planner_;
    std::unique_ptr<PlanSink> sink_;
    std::unique_ptr<machine_program::MachineExecutor> executor_;  // saves settings changes
    std::unique_ptr<interp::MachineQuery> machine_;               // what #CURMACHPOS & co. read
    std::unique_ptr<interp::Interpreter> interpreter_;
    std::unique_ptr<interp::wire::Decoder> decoder_;  // stream mode
    std::deque<motion::PreparedSegment> outbox_;      // planned, in order, not yet in the ring
    // Synchronised outputs waiting for the first record of move `from_move_id` or later, in
    // program order (the planner's window may hold several moves, each with its own).
    struct PendingOutputs {
        std::uint64_t set = 0, clear = 0;
        std::uint32_t from_move_id = 0;
        std::int32_t line = 0;
        std::uint32_t message = 0;  // the last M801 message due with them, 0: none
    };
    PendingOutputs& pending_for(std::uint32_t from_move_id, std::int32_t line);
    std::uint32_t messages_ = 0;  // M801 messages planned so far
    std::deque<PendingOutputs> pending_outputs_;
    bool program_done_ = false;  // interpreter ended (or failed), planner finished

    std::atomic<bool> abandoned_{false};
    std::atomic<bool> idle_{false};
    std::atomic<bool> failed_{false};
    std::atomic<std::uint32_t> ignored_{0};

    // Barriers: count << 1 | (1 while standing at the latest one). Written by the feeder thread;
    // the servo thread reads it once per period in idle() and keeps what it saw for
    // acknowledge(), so the two agree within a period.
    bool barrier_pending_ = false;  // a Sync decoded, records before it not yet all delivered
    std::uint32_t barriers_ = 0;
    std::atomic<std::uint64_t> barrier_state_{0};
    mutable std::uint64_t seen_barrier_state_ = 0;  // servo thread only
    std::uint32_t acknowledged_ = 0;                // servo thread only

    // Conditional moves: the feeder queues one and waits; the servo thread writes the result
    // and then counts it in probes_done_ (release), which the feeder reads (acquire).
    bool probe_pending_ = false;    // feeder thread
    bool probe_announced_ = false;  // counted in probes_sent_
    interp::canon::ConditionalMove probe_cmd_;
    std::string probe_file_;       // of the G904
    interp::SourceLoc probe_loc_;  // of the G904, its file viewing probe_file_
    std::atomic<std::uint32_t> probes_sent_{0};
    std::atomic<std::uint32_t> probes_done_{0};
    motion::AxisArray probe_pos_mm_{};
    motion::AxisArray probe_trip_mm_{};
    bool probe_tripped_ = false;

    mutable std::mutex mutex_;
    std::string error_;
    std::string stream_file_;         // guarded by mutex_
    bool stream_file_known_ = false;  // feeder thread only
    hal::Worker worker_;              // last: joins the thread before the state it uses goes
};

// A record that holds `pos_mm` for `seconds` (a dwell), ending at rest like a program end.
motion::PreparedSegment dwell_record(const motion::AxisArray& pos_mm, double seconds,
                                     std::int32_t line, double max_rate);

}  // namespace motioncomp
