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
    if (thread_.joinable() || idle()) return false;
    pause_.store(false, std::memory_order_relaxed);
    {
        std::lock_guard lock(mutex_);
        ready_ = false;
    }
    thread_ = std::thread([this] { run(); });
    std::unique_lock lock(mutex_);
    ready_cv_.wait(lock, [this] { return ready_; });
    return failed_at_ready_;
}

void ProgramFeeder::stop() {
    pause_.store(true, std::memory_order_relaxed);
    if (thread_.joinable()) thread_.join();
}

void ProgramFeeder::wait_for_lead() const noexcept {
    while (!idle() && !abandoned_.load(std::memory_order_relaxed) && ring_.free_slots() > 0)
        std::this_thread::yield();
}

std::string ProgramFeeder::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

void ProgramFeeder::mark_ready() {
    std::lock_guard lock(mutex_);
    if (ready_) return;
    ready_ = true;
    failed_at_ready_ = failed();
    ready_cv_.notify_all();
}

bool ProgramFeeder::stopping() const noexcept {
    return pause_.load(std::memory_order_relaxed) || abandoned_.load(std::memory_order_relaxed);
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
        if (program_done_ && outbox_.empty()) break;
        if (program_done_ || outbox_.size() >= kOutboxLimit) {
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
        }
        try {
            if (!interpreter_->step()) {
                planner_->finish();
                collect();
                program_done_ = true;
            }
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }
    if ((program_done_ && outbox_.empty()) || abandoned_.load(std::memory_order_relaxed))
        idle_.store(true, std::memory_order_release);
    mark_ready();
}

}  // namespace motioncomp
