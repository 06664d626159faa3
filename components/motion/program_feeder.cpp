#include "program_feeder.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>

#include "../machine_state.hpp"
#include "../probe_result.hpp"
#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"
#include "interp/dialect.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "plan_sink.hpp"

namespace motioncomp {

namespace {

// What the in-process interpreter's named parameters read. Positions are where the machine
// stands once everything planned so far has run; the rest is the executor's model. The two
// positions differ only after a conditional move (G904): the model takes the trip point (see
// take_probe_result), while the machine stopped a braking distance beyond it and stays there
// until the next move. #CURMACHPOS is then that stop point, as the interp component reads it
// live from interp.machine-pos-L, and #CURWORKPOS moves with it (work = machine - offsets).
class StandingMachine final : public machine_program::ModelQuery {
  public:
    StandingMachine(interp::Executor& exec, const PlanSink& sink) : ModelQuery(exec), sink_(sink) {}

    double machine_pos_mm(interp::Axis axis) override {
        const std::optional<motion::AxisArray> stand_mm = sink_.standing_off_path_mm();
        return stand_mm ? (*stand_mm)[static_cast<std::size_t>(axis)] : exec_.machine_pos_mm(axis);
    }

  private:
    const PlanSink& sink_;
};

}  // namespace

ProgramFeeder::ProgramFeeder(FeederConfig cfg, motion::SpscRing<motion::PreparedSegment>& ring)
    : cfg_(std::move(cfg)), ring_(ring) {}

ProgramFeeder::~ProgramFeeder() {
    stop();
}

// Also after the program is over (idle): the thread comes back to linger until the next stop(),
// so a fault after a stop and start is published at once as well.
bool ProgramFeeder::start_and_wait_ready() {
    if (worker_.running()) return false;
    return worker_.start_and_wait_ready([this] { run(); });
}

void ProgramFeeder::stop() {
    worker_.pause_and_join();
}

bool ProgramFeeder::idle() const noexcept {
    seen_barrier_state_ = barrier_state_.load(std::memory_order_acquire);
    return idle_.load(std::memory_order_acquire) || (seen_barrier_state_ & 1) != 0;
}

std::uint32_t ProgramFeeder::acknowledge(bool in_position) noexcept {
    // In position with the feeder idle: every record up to the barrier it stood at when idle()
    // looked has been followed to the end.
    if (in_position) acknowledged_ = static_cast<std::uint32_t>(seen_barrier_state_ >> 1);
    return acknowledged_;
}

void ProgramFeeder::await_probe(const interp::SourceLoc& loc,
                                const interp::canon::ConditionalMove& cm) {
    probe_pending_ = true;
    probe_cmd_ = cm;
    probe_file_ = loc.file;
    probe_loc_ = interp::SourceLoc{probe_file_, loc.line, loc.col};
}

void ProgramFeeder::report_probe(const motion::AxisArray& pos_mm, const motion::AxisArray& trip_mm,
                                 bool tripped) noexcept {
    probe_pos_mm_ = pos_mm;
    probe_trip_mm_ = trip_mm;
    probe_tripped_ = tripped;
    probes_done_.fetch_add(1, std::memory_order_release);
}

bool ProgramFeeder::probe_result_waiting() const noexcept {
    return probes_done_.load(std::memory_order_acquire) <
           probes_sent_.load(std::memory_order_acquire);
}

// The path goes on from where the conditional move stopped. With the interpreter in-process
// its model takes the point where the inputs came (machine_program::adopt_probe_result; the
// machine stands a braking distance beyond it, which #CURMACHPOS reads: StandingMachine), and a
// move that ended without its inputs throws the alarm NCX-3 asks for; with the interp
// component, that component does both (it waits at the barrier it sends after a G904 and reads
// motion.probe-pos-L and motion.probe-tripped).
void ProgramFeeder::take_probe_result() {
    probe_pending_ = false;
    sink_->restart_from(probe_pos_mm_);
    if (!executor_) return;
    const motion::AxisArray machine_mm = sink_->to_machine(probe_trip_mm_);
    machine_program::adopt_probe_result(
        executor_->executor(), probe_loc_, probe_cmd_, probe_tripped_,
        [&machine_mm](int axis) { return machine_mm[static_cast<std::size_t>(axis)]; });
}

void ProgramFeeder::wait_for_lead() const noexcept {
    // A ring at least half full already holds more than one period can use (a period would
    // need records shorter than a 2000th of its travel each), so the period runs as it would
    // with a full ring. Below that the ring is topped up completely: waiting every period for
    // the one or two records it used cost more than the planning (surface programs ran at 2x
    // real time).
    if (ring_.size() >= ring_.capacity() / 2) return;
    if (probe_result_waiting()) return;  // the machine has to make the conditional move first
    // Also returns at a barrier motion has not reached yet (it must run there first); at one it
    // has acknowledged, it waits for the interpreter to go on, so the first period after a
    // queue-busting read is the same on every run.
    while (!idle_.load(std::memory_order_acquire) && !abandoned_.load(std::memory_order_relaxed) &&
           ring_.free_slots() > 0) {
        const std::uint64_t b = barrier_state_.load(std::memory_order_acquire);
        if ((b & 1) && acknowledged_ < (b >> 1)) return;
        if (probe_result_waiting()) return;
        std::this_thread::yield();
    }
}

void ProgramFeeder::remember_stream_file(std::string_view file) {
    std::lock_guard lock(mutex_);
    stream_file_ = file;
    stream_file_known_ = true;
}

std::string ProgramFeeder::program_file() const {
    if (!cfg_.program_path.empty()) return cfg_.program_path;
    std::lock_guard lock(mutex_);
    return stream_file_;
}

std::string ProgramFeeder::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

void ProgramFeeder::mark_ready() {
    worker_.mark_ready(failed());
}

bool ProgramFeeder::stopping() const noexcept {
    return worker_.pause_requested() || abandoned_.load(std::memory_order_relaxed);
}

namespace {
// Applies `bits` after what `set` / `clear` already hold: the later command wins for a port.
void merge_outputs(std::uint64_t& set, std::uint64_t& clear, std::uint64_t set_bits,
                   std::uint64_t clear_bits) {
    set = (set & ~clear_bits) | set_bits;
    clear = (clear & ~set_bits) | clear_bits;
}
}  // namespace

void ProgramFeeder::collect(const motion::PreparedSegment* extra) {
    // Copied once, straight into the outbox (pop() would copy each record twice).
    while (const motion::PreparedSegment* ready = planner_->pop_ref()) {
        motion::PreparedSegment& rec = outbox_.emplace_back(*ready);
        while (!pending_outputs_.empty() && rec.move_id >= pending_outputs_.front().from_move_id) {
            const PendingOutputs& p = pending_outputs_.front();
            merge_outputs(rec.dout_set, rec.dout_clear, p.set, p.clear);
            rec.message = std::max(rec.message, p.message);
            pending_outputs_.pop_front();
        }
    }
    if (extra) outbox_.push_back(*extra);
}

void ProgramFeeder::collect_at_rest(const motion::AxisArray& pos_mm,
                                    const motion::PreparedSegment* extra) {
    collect();
    // No move follows before the rest: the outputs change here, one standing record each.
    for (const PendingOutputs& p : pending_outputs_) {
        for (int port = 0; port < 64; ++port) {
            const std::uint64_t bit = std::uint64_t{1} << port;
            if (!((p.set | p.clear) & bit)) continue;
            const motion::Action a{motion::ActionKind::SetOutput, (p.set & bit) != 0, port, 0};
            outbox_.push_back(motion::action_record(pos_mm, a, p.line));
        }
        if (p.message == 0) continue;
        const motion::Action m{motion::ActionKind::Message, false,
                               static_cast<std::int32_t>(p.message), 0};
        outbox_.push_back(motion::action_record(pos_mm, m, p.line));
    }
    pending_outputs_.clear();
    if (extra) outbox_.push_back(*extra);
}

ProgramFeeder::PendingOutputs& ProgramFeeder::pending_for(std::uint32_t from_move_id,
                                                          std::int32_t line) {
    if (pending_outputs_.empty() || pending_outputs_.back().from_move_id != from_move_id)
        pending_outputs_.push_back({0, 0, from_move_id, line});
    PendingOutputs& p = pending_outputs_.back();
    p.line = line;
    return p;
}

void ProgramFeeder::sync_output(int port, bool level, std::uint32_t from_move_id,
                                std::int32_t line) {
    PendingOutputs& p = pending_for(from_move_id, line);
    const std::uint64_t bit = std::uint64_t{1} << port;
    merge_outputs(p.set, p.clear, level ? bit : 0, level ? 0 : bit);
}

void ProgramFeeder::sync_message(const interp::Canon& message, std::uint32_t from_move_id) {
    pending_for(from_move_id, message.loc.line).message = ++messages_;
    post_text(message);
}

void ProgramFeeder::post_text(const interp::Canon& text) {
    if (cfg_.on_text) cfg_.on_text(text);
}

void ProgramFeeder::deliver() noexcept {
    while (!outbox_.empty() && ring_.try_push(outbox_.front())) outbox_.pop_front();
}

void ProgramFeeder::fail(const std::exception& e) {
    {
        std::lock_guard lock(mutex_);
        error_ = e.what();
    }
    failed_.store(true, std::memory_order_release);
    if (cfg_.on_error) {
        // interp::Error (the interpreter's, the sink's refusals, the stream's end record with
        // a place) keeps its place apart from its cause; anything else has none.
        if (const auto* located = dynamic_cast<const interp::Error*>(&e))
            cfg_.on_error(interp::SourceLoc{located->file(), located->line(), located->col()},
                          located->reason());
        else
            cfg_.on_error(std::nullopt, e.what());
    }
    // Motion already planned stays valid: it runs out to rest.
    planner_->finish();
    collect_at_rest(planner_->end_position(), nullptr);
    program_done_ = true;
}

void ProgramFeeder::open_program() {
    planner_ = std::make_unique<motion::Planner>(cfg_.plan, motion::AxisArray{});
    sink_ = make_plan_sink(*planner_, cfg_, *this);
    if (cfg_.canon_source) {
        decoder_ = std::make_unique<interp::wire::Decoder>();
        return;
    }
    executor_ = std::make_unique<machine_program::MachineExecutor>(*sink_, cfg_.program_options);
    machine_ = std::make_unique<StandingMachine>(executor_->executor(), *sink_);
    interpreter_ = std::make_unique<interp::Interpreter>(
        *executor_, *machine_, machine_program::interpreter_options(cfg_.program_options));
    machine_program::open_program(*interpreter_, cfg_.program_options, cfg_.program_path);
}

void ProgramFeeder::run() noexcept {
    // Interpreting runs ahead of the ring by at most this many records; more would only
    // cost memory, since the servo side cannot use them before the ring has room.
    constexpr std::size_t kOutboxLimit = 256;
    if (!planner_) {
        try {
            open_program();
        } catch (const std::exception& e) {
            if (!planner_)
                planner_ = std::make_unique<motion::Planner>(cfg_.plan, motion::AxisArray{});
            fail(e);
        }
    }
    while (!stopping()) {
        poll_owner();
        deliver();
        if (ring_.free_slots() == 0) mark_ready();  // a full lead: start() may return
        reach_barrier_if_delivered();
        if (program_done_ && outbox_.empty()) break;
        if (probe_pending_ && !program_done_) {
            // Announced only once everything up to the conditional move is in the ring, so the
            // lock-step servo function sees the same queue on every run.
            if (!probe_announced_ && outbox_.empty()) {
                probe_announced_ = true;
                probes_sent_.fetch_add(1, std::memory_order_release);
                mark_ready();  // start() may return: the machine has to move first
            }
            if (!probe_announced_ || probe_result_waiting()) {
                std::this_thread::sleep_for(std::chrono::microseconds(100));
                continue;
            }
            probe_announced_ = false;
            try {
                take_probe_result();
            } catch (const std::exception& e) {
                fail(e);
            }
            continue;
        }
        if (program_done_ || outbox_.size() >= kOutboxLimit || barrier_pending_) {
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        try {
            switch (step()) {
                case Progress::End:
                    planner_->finish();
                    collect_at_rest(planner_->end_position(), nullptr);
                    program_done_ = true;
                    break;
                case Progress::Starved:  // the interp component has not sent more yet
                    std::this_thread::sleep_for(std::chrono::microseconds(50));
                    break;
                case Progress::More:
                    break;
            }
        } catch (const std::exception& e) {
            fail(e);
        }
    }
    if ((program_done_ && outbox_.empty()) || abandoned_.load(std::memory_order_relaxed))
        idle_.store(true, std::memory_order_release);
    mark_ready();
    linger();
}

// The program is over (or abandoned, which a servo fault does in the period it is seen), but
// the machine may stay loaded and fault later, or has just faulted: the thread stays, the
// stream's producer, until stop() joins it. Polling, because the servo function may not wake
// a thread (a futex is a system call); a millisecond is far below what an operator notices
// and costs nothing next to the planning loop's own 50-200 us naps.
void ProgramFeeder::linger() noexcept {
    while (!worker_.pause_requested()) {
        poll_owner();
        std::this_thread::sleep_for(kLingerPoll);
    }
}

void ProgramFeeder::poll_owner() noexcept {
    if (!cfg_.on_poll) return;
    try {
        cfg_.on_poll();
    } catch (const std::exception&) {
        // Out of memory formatting a text: the owner tries again at the next poll, and its
        // own report at stop() comes after this thread is joined.
    }
}

ProgramFeeder::Progress ProgramFeeder::step() {
    if (cfg_.canon_source) return read_stream();
    return interpreter_->step() ? Progress::More : Progress::End;
}

// One command from the stream per call, as the in-process interpreter gives one line per step.
ProgramFeeder::Progress ProgramFeeder::read_stream() {
    interp::wire::Record r;
    while (cfg_.canon_source(r)) {
        leave_barrier();
        switch (decoder_->feed(r)) {
            case interp::wire::Decoder::Item::None:
                continue;
            case interp::wire::Decoder::Item::End:
                if (!decoder_->failed()) return Progress::End;
                if (const auto& where = decoder_->error_loc())
                    throw interp::Error(*where, decoder_->error_cause());
                throw std::runtime_error(decoder_->error());
            case interp::wire::Decoder::Item::Command: {
                const interp::Canon& c = decoder_->command();
                if (!stream_file_known_) remember_stream_file(c.loc.file);
                sink_->emit(c);
                if (std::holds_alternative<interp::canon::Sync>(c.cmd)) {
                    // Whatever the sink made of it, the machine must come to rest here.
                    planner_->finish();
                    collect_at_rest(planner_->end_position(), nullptr);
                    barrier_pending_ = true;
                }
                return Progress::More;
            }
        }
    }
    return Progress::Starved;
}

void ProgramFeeder::reach_barrier_if_delivered() {
    if (!barrier_pending_ || !outbox_.empty()) return;
    barrier_pending_ = false;
    ++barriers_;
    barrier_state_.store(std::uint64_t{barriers_} << 1 | 1, std::memory_order_release);
    mark_ready();  // start() may return: the machine has to move before anything more comes
}

void ProgramFeeder::leave_barrier() noexcept {
    if (barrier_state_.load(std::memory_order_relaxed) & 1)
        barrier_state_.store(std::uint64_t{barriers_} << 1, std::memory_order_release);
}

}  // namespace motioncomp
