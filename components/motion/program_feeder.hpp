// The non-realtime side of the motion component: a thread that runs the interpreter on a
// program file, turns its canonical commands into planner segments and keeps the realtime
// ring filled with prepared records. HAL-free; motion.cpp owns it.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "motion/planner.hpp"
#include "motion/prepared.hpp"
#include "motion/spsc_ring.hpp"

namespace motioncomp {

struct FeederConfig {
    std::string program_path;
    std::string dialect;  // empty: the interpreter's default (ncstudio)
    motion::PlannerConfig plan;
    std::array<bool, motion::kAxes> axis_present{};  // axes named by coordinates=
    std::string coordinates;                         // for error messages
    double blend_tolerance_mm = 0;
};

class ProgramFeeder {
  public:
    ProgramFeeder(FeederConfig cfg, motion::SpscRing<motion::PreparedSegment>& ring);
    ~ProgramFeeder();
    ProgramFeeder(const ProgramFeeder&) = delete;
    ProgramFeeder& operator=(const ProgramFeeder&) = delete;

    // Configuration world. Starts the thread and blocks until the whole program is planned
    // and in the ring, the ring is full, or the program failed. This is what makes a
    // simulated-clock run deterministic: the servo function never sees a half-planned queue
    // unless the program is longer than the ring.
    void start_and_wait_ready();
    // Configuration world: cancels planning and joins the thread.
    void stop();

    // Realtime-safe: asks the thread to stop feeding (abort).
    void cancel() noexcept { cancel_.store(true, std::memory_order_relaxed); }

    // Realtime-safe status.
    bool idle() const noexcept { return idle_.load(std::memory_order_acquire); }
    bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }
    std::uint32_t ignored_commands() const noexcept {
        return ignored_.load(std::memory_order_relaxed);
    }
    // Configuration world, valid once failed() is true: "file:line[:col]: reason".
    std::string error() const;

  private:
    void run() noexcept;
    void plan_program();
    // Moves planned records into the ring; waits for room unless `block` is false or
    // planning was cancelled. Returns false if it gave up with records still pending.
    bool flush(motion::Planner& planner, bool block);
    void mark_ready();

    FeederConfig cfg_;
    motion::SpscRing<motion::PreparedSegment>& ring_;
    motion::PreparedSegment pending_{};
    bool have_pending_ = false;

    std::thread thread_;
    std::atomic<bool> cancel_{false};
    std::atomic<bool> idle_{false};
    std::atomic<bool> failed_{false};
    std::atomic<std::uint32_t> ignored_{0};

    mutable std::mutex mutex_;
    std::condition_variable ready_cv_;
    bool ready_ = false;
    std::string error_;
};

// A record that holds `pos_mm` for `seconds` (a dwell), ending at rest like a program end.
motion::PreparedSegment dwell_record(const motion::AxisArray& pos_mm, double seconds,
                                     std::int32_t line, double max_rate);

}  // namespace motioncomp
