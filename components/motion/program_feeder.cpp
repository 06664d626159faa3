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

namespace motioncomp {

namespace {

constexpr char kAxisLetters[] = "XYZABCUVW";

// The interpreter's machine axes (X Y Z A B C) are the first of the planner's nine.
motion::AxisArray to_axes(const interp::AxisVec& v) {
    motion::AxisArray out{};
    for (int k = 0; k < interp::kMachineAxes && k < motion::kAxes; ++k) out[k] = v[k];
    return out;
}

// Turns canonical commands into planner input. Commands without a motion meaning for this
// component (spindle, coolant, I/O, tool changes, waits, messages) are counted, not obeyed.
class PlanSink final : public interp::CanonSink {
  public:
    PlanSink(motion::Planner& planner, const FeederConfig& cfg, ProgramFeeder& feeder)
        : planner_(planner), cfg_(cfg), feeder_(feeder), pos_mm_(planner.end_position()) {}

    void emit(const interp::Canon& c) override {
        std::visit([&](const auto& cmd) { handle(c.loc, cmd); }, c.cmd);
    }

  private:
    void handle(const interp::SourceLoc& loc, const interp::canon::Traverse& t) {
        motion::PathSegment seg = base_segment(loc, t.end_mm);
        seg.rapid = true;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::FeedLine& f) {
        motion::PathSegment seg = base_segment(loc, f.end_mm);
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Arc& a) {
        motion::PathSegment seg = base_segment(loc, a.end_mm);
        seg.kind = motion::SegmentKind::Arc;
        const interp::PlaneAxes axes = interp::plane_axes(a.plane);
        seg.plane_first = axes.first;
        seg.plane_second = axes.second;
        seg.plane_normal = axes.normal;
        seg.centre_mm = {a.centre_mm[axes.first], a.centre_mm[axes.second]};
        seg.turns = a.turns;
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedRate& f) {
        feed_mm_s_ = f.feed_mm_s;
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Dwell& d) {
        // The planner has no pause element: end the motion at rest, then queue a record that
        // stands still for the dwell time.
        planner_.finish();
        if (d.seconds > 0) {
            const motion::PreparedSegment rec =
                dwell_record(pos_mm_, d.seconds, loc.line, cfg_.plan.max_rate);
            feeder_.collect(&rec);
        } else {
            feeder_.collect();
        }
    }
    void handle(const interp::SourceLoc&, const interp::canon::ProgramEnd&) {
        planner_.finish();
        feeder_.collect();
    }
    // Informational: end points already include offsets, units and plane are per move.
    void handle(const interp::SourceLoc&, const interp::canon::Offsets&) {}
    void handle(const interp::SourceLoc&, const interp::canon::ToolOffset&) {}
    void handle(const interp::SourceLoc&, const interp::canon::Units&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SelectPlane&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedMode&) {}
    template <class Other>
    void handle(const interp::SourceLoc&, const Other&) {
        feeder_.count_ignored();
    }

    motion::PathSegment base_segment(const interp::SourceLoc& loc, const interp::AxisVec& end) {
        motion::PathSegment seg;
        seg.end_mm = to_axes(end);
        seg.tolerance_mm = cfg_.blend_tolerance_mm;
        seg.line = loc.line;
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k] && std::fabs(seg.end_mm[k] - pos_mm_[k]) > 1e-9)
                throw std::runtime_error(
                    fmt::format("{}:{}:{}: axis {} moves but the machine has only coordinates={}",
                                loc.file, loc.line, loc.col, kAxisLetters[k], cfg_.coordinates));
        }
        return seg;
    }

    void push(const interp::SourceLoc& loc, const motion::PathSegment& seg) {
        try {
            planner_.push(seg);
        } catch (const motion::PlanError& e) {
            // PlanError says "line N: reason"; the user needs the file too.
            std::string reason = e.what();
            const auto colon = reason.find(": ");
            if (colon != std::string::npos) reason.erase(0, colon + 2);
            throw std::runtime_error(
                fmt::format("{}:{}:{}: {}", loc.file, loc.line, loc.col, reason));
        }
        pos_mm_ = seg.end_mm;
        feeder_.collect();
    }

    motion::Planner& planner_;
    const FeederConfig& cfg_;
    ProgramFeeder& feeder_;
    motion::AxisArray pos_mm_;
    double feed_mm_s_ = 0;
};

}  // namespace

motion::PreparedSegment dwell_record(const motion::AxisArray& pos_mm, double seconds,
                                     std::int32_t line, double max_rate) {
    motion::PreparedSegment rec{};
    rec.geom = motion::make_line(pos_mm, pos_mm);
    rec.profile.count = 1;  // one phase at rest: s = 0 throughout
    rec.profile.duration_s = seconds;
    rec.phase_rate_cap.fill(max_rate);  // nothing moves, so no rate can exceed a limit
    rec.line = line;
    rec.program_end = true;
    return rec;
}

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
    sink_ = std::make_unique<PlanSink>(*planner_, cfg_, *this);
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping program would plan forever
    if (!cfg_.dialect.empty()) options.dialect = interp::find_dialect(cfg_.dialect);
    executor_ = std::make_unique<interp::Executor>(*sink_, interp::BackendConfig{});
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
