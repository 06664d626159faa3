#include "program_runner.hpp"

#include <fmt/format.h>

#include <chrono>
#include <exception>
#include <utility>
#include <variant>

#include "../machine_state.hpp"
#include "../probe_result.hpp"
#include "interp/canon.hpp"
#include "interp/dialect.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace interpcomp {

namespace {
// Interpreting runs ahead of the stream by at most this many records: more would only cost
// memory, as the consumer cannot take them before the stream has room.
constexpr std::size_t kOutboxLimit = 256;
constexpr auto kPollInterval = std::chrono::microseconds(100);
}  // namespace

// The executor's sink: commands go to the stream; a Sync (G906) is a barrier to wait at.
class ProgramRunner::Sink final : public interp::CanonSink {
  public:
    explicit Sink(ProgramRunner& runner) : runner_(runner) {}
    void emit(const interp::Canon& c) override {
        if (std::holds_alternative<interp::canon::Sync>(c.cmd)) {
            runner_.sync(c.loc);
            return;
        }
        runner_.send(c);
        if (const auto* cm = std::get_if<interp::canon::ConditionalMove>(&c.cmd))
            runner_.adopt_probe_result(c.loc, *cm);
    }

  private:
    ProgramRunner& runner_;
};

// What named parameters read. Positions, inputs, outputs and the spindle speed are the
// machine's live ones after a barrier (motion has followed everything sent and stands in
// position); modal state and settings come from the executor's model. Standalone, everything
// comes from the model.
class ProgramRunner::LiveMachine final : public machine_program::ModelQuery {
  public:
    LiveMachine(ProgramRunner& runner, interp::Executor& exec) : ModelQuery(exec), runner_(runner) {}

    double machine_pos_mm(interp::Axis axis) override {
        if (runner_.cfg_.standalone) return exec_.machine_pos_mm(axis);
        sync_if_behind();
        return runner_.link_.machine_pos_mm(static_cast<int>(axis));
    }
    std::uint64_t input_bits() override {
        if (runner_.cfg_.standalone) return exec_.input_bits();
        sync_if_behind();
        return runner_.link_.input_bits();
    }
    std::uint64_t output_bits() override {
        if (runner_.cfg_.standalone) return exec_.output_bits();
        sync_if_behind();
        return runner_.link_.output_bits();
    }
    double spindle_rpm() override {
        if (runner_.cfg_.standalone) return exec_.spindle_rpm();
        sync_if_behind();
        return runner_.link_.spindle_rpm();
    }

  private:
    void sync_if_behind() {
        if (!runner_.machine_current()) runner_.sync(runner_.last_loc_);
    }

    ProgramRunner& runner_;
};

ProgramRunner::ProgramRunner(RunnerConfig cfg, MachineLink& link)
    : cfg_(std::move(cfg)), link_(link) {}

ProgramRunner::~ProgramRunner() {
    stop();
}

bool ProgramRunner::start_and_wait_ready() {
    if (worker_.running() || done() || failed()) return failed();
    running_.store(true, std::memory_order_relaxed);
    return worker_.start_and_wait_ready([this] { run(); });
}

void ProgramRunner::stop() {
    worker_.pause_and_join();
    running_.store(false, std::memory_order_relaxed);
}

std::string ProgramRunner::error() const {
    std::lock_guard lock(mutex_);
    return error_;
}

bool ProgramRunner::stopping() noexcept {
    if (link_.abort_requested()) abort_.store(true, std::memory_order_relaxed);
    return worker_.pause_requested() || abort_.load(std::memory_order_relaxed);
}

void ProgramRunner::mark_ready() {
    worker_.mark_ready(failed());
}

void ProgramRunner::send(const interp::Canon& c) {
    scratch_.clear();
    encoder_.command(c, scratch_);
    outbox_.insert(outbox_.end(), scratch_.begin(), scratch_.end());
    last_loc_ = c.loc;
    line_.store(c.loc.line, std::memory_order_relaxed);
    current_ = false;
}

void ProgramRunner::sync(const interp::SourceLoc& loc) {
    send(interp::Canon{loc, interp::canon::Sync{}});
    if (cfg_.standalone) return;
    const std::uint32_t target = barriers_.fetch_add(1, std::memory_order_relaxed) + 1;
    waiting_.store(true, std::memory_order_relaxed);
    while (!(deliver() && link_.barriers_reached() >= target)) {
        if (stopping()) {
            waiting_.store(false, std::memory_order_relaxed);
            throw Stopped{};
        }
        mark_ready();  // start() returns: the machine must move before the program goes on
        link_.on_progress();
        std::this_thread::sleep_for(kPollInterval);
    }
    waiting_.store(false, std::memory_order_relaxed);
    current_ = true;
}

void ProgramRunner::adopt_probe_result(const interp::SourceLoc& loc,
                                       const interp::canon::ConditionalMove& cm) {
    if (cfg_.standalone) return;  // the executor's model (g904_trip_mm) stands in
    sync(loc);
    machine_program::adopt_probe_result(backend_->executor(), loc, cm, link_.probe_tripped(),
                                        [this](int axis) { return link_.probe_pos_mm(axis); });
}

bool ProgramRunner::deliver() noexcept {
    while (!outbox_.empty() && link_.push(outbox_.front())) outbox_.pop_front();
    return outbox_.empty();
}

// The end record goes last; done/failed are set before it can reach the consumer, so whoever
// sees the machine stop after the program's end also sees why.
void ProgramRunner::finish(const std::string& error, const interp::SourceLoc* place,
                           std::string_view cause) {
    if (error.empty()) {
        done_.store(true, std::memory_order_release);
    } else {
        {
            std::lock_guard lock(mutex_);
            error_ = error;
        }
        failed_.store(true, std::memory_order_release);
    }
    scratch_.clear();
    if (place)
        encoder_.end(*place, cause, scratch_);
    else
        encoder_.end(error, scratch_);
    outbox_.insert(outbox_.end(), scratch_.begin(), scratch_.end());
    finished_ = true;
    running_.store(false, std::memory_order_relaxed);
    link_.on_progress();
}

void ProgramRunner::fail_with(const interp::Error& e) {
    const interp::SourceLoc place{e.file(), e.line(), e.col()};
    finish(e.what(), &place, e.reason());
}

// Stopped or aborted before the program's end: the place is the last command sent (what the
// machine was doing), or the program itself when nothing was sent yet.
void ProgramRunner::give_up(std::string_view why) {
    const std::string cause = fmt::format("{}; the rest of the program is given up", why);
    if (last_loc_.line == 0) return finish(fmt::format("{}: {}", cfg_.program_path, cause));
    fail_with(interp::Error(last_loc_, cause));  // its what() is the place and the cause
}

void ProgramRunner::open_program() {
    sink_ = std::make_unique<Sink>(*this);
    backend_ = std::make_unique<machine_program::MachineExecutor>(*sink_, cfg_.options);
    machine_ = std::make_unique<LiveMachine>(*this, backend_->executor());
    interpreter_ = std::make_unique<interp::Interpreter>(
        *backend_, *machine_, machine_program::interpreter_options(cfg_.options));
    machine_program::open_program(*interpreter_, cfg_.options, cfg_.program_path);
}

void ProgramRunner::run() noexcept {
    if (!interpreter_ && !finished_) {
        try {
            open_program();
        } catch (const interp::Error& e) {
            fail_with(e);
        } catch (const std::exception& e) {
            finish(e.what());
        }
    }
    while (!worker_.pause_requested()) {
        const bool all_sent = deliver();
        if (finished_ && all_sent) break;
        if (!all_sent) mark_ready();  // the stream is full
        if (finished_ || outbox_.size() >= kOutboxLimit) {
            std::this_thread::sleep_for(kPollInterval);
            continue;
        }
        link_.on_progress();
        if (stopping()) {
            if (worker_.pause_requested()) break;
            give_up("aborted");
            continue;
        }
        try {
            if (!interpreter_->step()) finish("");
        } catch (const Stopped&) {
            // The block that asked could not be finished: the rest of the program is given up.
            give_up(abort_.load(std::memory_order_relaxed)
                        ? "aborted while waiting for the machine"
                        : "stopped while waiting for the machine");
        } catch (const interp::Error& e) {
            fail_with(e);
        } catch (const std::exception& e) {
            finish(e.what());
        }
    }
    link_.on_progress();
    mark_ready();
}

}  // namespace interpcomp
