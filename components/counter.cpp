// counter: single-input pulse counter with index reset, LinuxCNC-compatible and, as there,
// deprecated in favour of `encoder` with counter-mode TRUE (`loadrt counter [num_chan=N]`).
// counter.update-counters (no floating point, fast thread) counts rising edges of phase-A and,
// while index-enable was TRUE at the last capture, zeroes the count on a rising edge of
// phase-Z and clears index-enable. counter.capture-position (floating point) applies reset
// and scaling and publishes counts, position and velocity.
//
// velocity is the number of phase-A edges since the previous capture, times 1/position-scale,
// divided by the capture thread's period; rawcounts counts every edge and is never reset. Both,
// like the other outputs, agree cycle by cycle with LinuxCNC 2.9
// (tests/hal/counter-linuxcnc-xcheck).
#include <atomic>
#include <cstdint>

#include "hal/component.hpp"

namespace {

struct Counter : hal::Instance {
    hal::In<bool> phase_a{this, "phase-A"};
    hal::In<bool> phase_z{this, "phase-Z"};
    hal::IO<bool> index_enable{this, "index-enable"};
    hal::In<bool> reset{this, "reset"};
    hal::Out<std::int32_t> counts{this, "counts"};
    hal::Out<std::int32_t> rawcounts{this, "rawcounts"};
    hal::Out<double> position{this, "position"};
    hal::Out<double> velocity{this, "velocity"};
    hal::IO<double> position_scale{this, "position-scale", 1.0};

    Counter() {
        shared_function<&Counter::update_counters>("update-counters", false);
        shared_function<&Counter::capture_position>("capture-position", true);
    }

    void update_counters(hal::Period) noexcept {
        const bool a = phase_a;
        if (a && !old_a_) {
            raw_.fetch_add(1, std::memory_order_relaxed);
            edges_.fetch_add(1, std::memory_order_relaxed);
        }
        old_a_ = a;
        const bool z = phase_z;
        if (z && !old_z_ && reset_on_index_.load(std::memory_order_acquire)) {
            raw_.store(0, std::memory_order_relaxed);
            reset_on_index_.store(false, std::memory_order_relaxed);
            index_enable = false;
        }
        old_z_ = z;
        // rawcounts counts every edge since loading and is never reset (as LinuxCNC 2.9's).
        rawcounts = static_cast<std::int32_t>(edges_.load(std::memory_order_relaxed));
    }

    void capture_position(hal::Period period) noexcept {
        if (reset) raw_.store(0, std::memory_order_relaxed);
        const std::int32_t n = raw_.load(std::memory_order_relaxed);
        counts = n;
        double s = position_scale;
        if (s != old_scale_) {
            if (s < 1e-20 && s > -1e-20) {
                s = 1.0;  // avoids dividing by zero; LinuxCNC repairs the pin the same way
                position_scale = s;
            }
            old_scale_ = s;
            scale_ = 1.0 / s;
        }
        position = n * scale_;
        const std::uint64_t edges = edges_.load(std::memory_order_relaxed);
        velocity = static_cast<double>(edges - seen_edges_) * scale_ / period.s;
        seen_edges_ = edges;
        reset_on_index_.store(index_enable, std::memory_order_release);
    }

  private:
    // update-counters side
    bool old_a_ = false;
    bool old_z_ = false;
    // shared between the two functions, which may run in different threads
    std::atomic<std::int32_t> raw_{0};
    std::atomic<std::uint64_t> edges_{0};
    std::atomic<bool> reset_on_index_{false};
    // capture-position side
    std::uint64_t seen_edges_ = 0;
    double old_scale_ = 1.0;
    double scale_ = 1.0;
};

}  // namespace

HAL_COMPONENT(counter, Counter, "counts input pulses (deprecated; use encoder)")
