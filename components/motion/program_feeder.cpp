#include "program_feeder.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>

#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"
#include "interp/dialect.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "plan_sink.hpp"

namespace motioncomp {

ProgramFeeder::ProgramFeeder(FeederConfig cfg, motion::SpscRing<motion::PreparedSegment>& ring)
    : cfg_(std::move(cfg)), ring_(ring) {}

ProgramFeeder::~ProgramFeeder() {
    stop();
}

bool ProgramFeeder::start_and_wait_ready() {
    if (worker_.running() || idle_.load(std::memory_order_acquire)) return false;
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

void ProgramFeeder::wait_for_lead() const noexcept {
    // A ring at least half full already holds more than one period can use (a period would
    // need records shorter than a 2000th of its travel each), so the period runs as it would
    // with a full ring. Below that the ring is topped up completely: waiting every period for
    // the one or two records it used cost more than the planning (surface programs ran at 2x
    // real time).
    if (ring_.size() >= ring_.capacity() / 2) return;
    // Also returns at a barrier motion has not reached yet (it must run there first); at one it
    // has acknowledged, it waits for the interpreter to go on, so the first period after a
    // queue-busting read is the same on every run.
    while (!idle_.load(std::memory_order_acquire) && !abandoned_.load(std::memory_order_relaxed) &&
           ring_.free_slots() > 0) {
        const std::uint64_t b = barrier_state_.load(std::memory_order_acquire);
        if ((b & 1) && acknowledged_ < (b >> 1)) return;
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

void ProgramFeeder::collect(const motion::PreparedSegment* extra) {
    motion::PreparedSegment rec;
    while (planner_->pop(rec)) outbox_.push_back(rec);
    if (extra) outbox_.push_back(*extra);
}

void ProgramFeeder::deliver() noexcept {
    while (!outbox_.empty() && ring_.try_push(outbox_.front())) outbox_.pop_front();
}

void ProgramFeeder::fail(const std::string& message) {
    {
        std::lock_guard lock(mutex_);
        error_ = message;
    }
    failed_.store(true, std::memory_order_release);
    // Motion already planned stays valid: it runs out to rest.
    planner_->finish();
    collect();
    program_done_ = true;
}

void ProgramFeeder::open_program() {
    planner_ = std::make_unique<motion::Planner>(cfg_.plan, motion::AxisArray{});
    sink_ = make_plan_sink(*planner_, cfg_, *this);
    if (cfg_.canon_source) {
        decoder_ = std::make_unique<interp::wire::Decoder>();
        return;
    }
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping program would plan forever
    if (!cfg_.dialect.empty()) options.dialect = interp::find_dialect(cfg_.dialect);
    interp::BackendConfig backend;
    backend.optional_stop = true;  // M01 reaches motion, which obeys motion.optional-stop
    executor_ = std::make_unique<interp::Executor>(*sink_, backend);
    interpreter_ = std::make_unique<interp::Interpreter>(*executor_, *executor_, options);
    interpreter_->open(cfg_.program_path);
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
            fail(e.what());
        }
    }
    while (!stopping()) {
        deliver();
        if (ring_.free_slots() == 0) mark_ready();  // a full lead: start() may return
        reach_barrier_if_delivered();
        if (program_done_ && outbox_.empty()) break;
        if (program_done_ || outbox_.size() >= kOutboxLimit || barrier_pending_) {
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        try {
            switch (step()) {
                case Progress::End:
                    planner_->finish();
                    collect();
                    program_done_ = true;
                    break;
                case Progress::Starved:  // the interp component has not sent more yet
                    std::this_thread::sleep_for(std::chrono::microseconds(50));
                    break;
                case Progress::More:
                    break;
            }
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }
    if ((program_done_ && outbox_.empty()) || abandoned_.load(std::memory_order_relaxed))
        idle_.store(true, std::memory_order_release);
    mark_ready();
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
                if (decoder_->failed()) throw std::runtime_error(decoder_->error());
                return Progress::End;
            case interp::wire::Decoder::Item::Command: {
                const interp::Canon& c = decoder_->command();
                if (!stream_file_known_) remember_stream_file(c.loc.file);
                sink_->emit(c);
                if (std::holds_alternative<interp::canon::Sync>(c.cmd)) {
                    // Whatever the sink made of it, the machine must come to rest here.
                    planner_->finish();
                    collect();
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
