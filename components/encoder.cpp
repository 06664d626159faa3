// encoder: software quadrature (or single-phase) counter, LinuxCNC-compatible (`loadrt
// encoder [num_chan=N | names=a,b]`). Two functions serve every channel at once, as in
// LinuxCNC: encoder.update-counters (no floating point; run it in a fast thread, at least
// twice the highest edge rate) samples the inputs and counts; encoder.capture-position (uses
// floating point; a slower servo thread is fine) turns the counts into counts, position,
// velocity and the latched values.
//
// Counting: a 4-state decoder per channel. x4-mode counts every edge of A and B; without it,
// one count per full quadrature cycle. counter-mode counts rising edges of A only. A step
// where A and B change together is ignored (no count), a single glitch counts up and back
// down. Index: while index-enable is TRUE, the next rising edge of phase-Z zeroes counts and
// position (by remembering the raw count there) and clears index-enable. reset zeroes them
// immediately. rawcounts is never reset.
//
// Missing-teeth index (counter-mode with missing-teeth = M > 0): a gap between rising edges of
// more than (M + 2) / 2 times the previous normal gap is taken as M missing teeth: the count
// jumps by M extra so that counts per revolution equal the full tooth count, and the edge
// after the gap acts as an index pulse. (LinuxCNC documents the feature but not its detection
// rule; this rule puts the threshold halfway between a normal and a gap interval.)
//
// Velocity: between captures that saw counts, velocity = counts / time between the count
// events that bounded them (much smoother than differencing position). With no new count it
// decays as if a count had just arrived, and drops to 0 once the time since the last count
// exceeds one count at min-speed-estimate. The first two capture periods with counts after a
// stop only restart the estimator.
//
// The two functions may run in different threads: update-counters publishes each event (count
// with its time stamp, index, latch) as one 64-bit atomic word, so capture-position never sees
// half an update.
#include <atomic>
#include <cmath>
#include <cstdint>

#include "hal/component.hpp"

namespace {

// Decoder tables, indexed by (previous A,B state << 2 | new A,B). Bit 6 = count up, bit 7 =
// count down, low nibble = the state to keep.
constexpr std::uint8_t kCountUp = 0x40;
constexpr std::uint8_t kCountDown = 0x80;
constexpr std::uint8_t kStateMask = 0x0F;
constexpr std::uint8_t kX4[16] = {0x00, 0x44, 0x88, 0x0C, 0x80, 0x04, 0x08, 0x4C,
                                  0x40, 0x04, 0x08, 0x8C, 0x00, 0x84, 0x48, 0x0C};
constexpr std::uint8_t kX1[16] = {0x00, 0x44, 0x08, 0x0C, 0x80, 0x04, 0x08, 0x0C,
                                  0x00, 0x04, 0x08, 0x0C, 0x00, 0x04, 0x08, 0x0C};
constexpr std::uint8_t kCounter[16] = {0x00, 0x48, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                       0x00, 0x08, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};

// Two 32-bit halves in one lock-free word: (sequence or time stamp, count).
std::uint64_t pack(std::uint32_t high, std::int32_t low) noexcept {
    return (std::uint64_t{high} << 32) | static_cast<std::uint32_t>(low);
}
std::uint32_t high_of(std::uint64_t w) noexcept {
    return static_cast<std::uint32_t>(w >> 32);
}
std::int32_t low_of(std::uint64_t w) noexcept {
    return static_cast<std::int32_t>(w & 0xFFFFFFFFu);
}
// Counts wrap around like the 32-bit hardware counters they model; signed overflow would be UB.
std::int32_t wrapping_add(std::int32_t a, std::int32_t b) noexcept {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) + static_cast<std::uint32_t>(b));
}
std::int32_t wrapping_sub(std::int32_t a, std::int32_t b) noexcept {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(a) - static_cast<std::uint32_t>(b));
}
static_assert(std::atomic<std::uint64_t>::is_always_lock_free,
              "update-counters and capture-position hand over events as lock-free 64-bit words");

struct Encoder : hal::Instance {
    hal::In<bool> phase_a{this, "phase-A"};
    hal::In<bool> phase_b{this, "phase-B"};
    hal::In<bool> phase_z{this, "phase-Z"};
    hal::IO<bool> index_enable{this, "index-enable"};
    hal::In<bool> reset{this, "reset"};
    hal::IO<bool> x4_mode{this, "x4-mode", true};
    hal::IO<bool> counter_mode{this, "counter-mode", false};
    hal::In<std::int32_t> missing_teeth{this, "missing-teeth"};
    hal::In<bool> latch_input{this, "latch-input"};
    hal::In<bool> latch_rising{this, "latch-rising", true};
    hal::In<bool> latch_falling{this, "latch-falling", true};
    hal::In<double> min_speed_estimate{this, "min-speed-estimate", 1.0};
    hal::IO<double> position_scale{this, "position-scale", 1.0};
    hal::Out<std::int32_t> rawcounts{this, "rawcounts"};
    hal::Out<std::int32_t> counts{this, "counts"};
    hal::Out<std::int32_t> counts_latched{this, "counts-latched"};
    hal::Out<double> position{this, "position"};
    hal::Out<double> position_interpolated{this, "position-interpolated"};
    hal::Out<double> position_latched{this, "position-latched"};
    hal::Out<double> velocity{this, "velocity"};
    hal::Out<double> velocity_rpm{this, "velocity-rpm"};

    Encoder() {
        shared_function<&Encoder::update_counters>("update-counters", false);
        shared_function<&Encoder::capture_position>("capture-position", true);
    }

    // ---- fast side: owns state_, raw_, old_z_, old_latch_, the edge timing and timebase_.
    void update_counters(hal::Period period) noexcept {
        const std::uint32_t now = timebase_.load(std::memory_order_relaxed);
        std::uint8_t state = state_;
        if (phase_a) state |= 0x01;
        if (phase_b) state |= 0x02;
        const bool counting = counter_mode;
        if (counting) {
            state = kCounter[state & (kStateMask & ~0x02)];
        } else {
            state = (x4_mode ? kX4 : kX1)[state & kStateMask];
        }
        bool gap_index = false;
        if (state & kCountUp) {
            raw_ = wrapping_add(raw_, 1);
            if (counting) gap_index = missing_teeth_gap(now);
        } else if (state & kCountDown) {
            raw_ = wrapping_sub(raw_, 1);
        }
        if (state & (kCountUp | kCountDown)) {
            count_event_.store(pack(now, raw_), std::memory_order_release);
        }
        state_ = state & kStateMask;
        rawcounts = raw_;

        const bool z = phase_z;
        if ((gap_index || (z && !old_z_)) && index_armed_.load(std::memory_order_acquire)) {
            index_armed_.store(false, std::memory_order_relaxed);
            index_event_.store(pack(++index_seq_, raw_), std::memory_order_release);
        }
        old_z_ = z;

        const bool latch = latch_input;
        if ((latch && !old_latch_ && latch_rising) || (!latch && old_latch_ && latch_falling)) {
            latch_event_.store(pack(++latch_seq_, raw_), std::memory_order_release);
        }
        old_latch_ = latch;
        timebase_.store(now + static_cast<std::uint32_t>(period.ns), std::memory_order_release);
    }

    // ---- slow side: owns everything the output pins show.
    void capture_position(hal::Period) noexcept {
        const std::uint64_t index = index_event_.load(std::memory_order_acquire);
        if (high_of(index) != seen_index_seq_) {
            seen_index_seq_ = high_of(index);
            index_count_ = low_of(index);
            index_enable = false;
        }
        const std::uint64_t latch = latch_event_.load(std::memory_order_acquire);
        if (high_of(latch) != seen_latch_seq_) {
            seen_latch_seq_ = high_of(latch);
            latch_count_ = low_of(latch);
        }
        index_armed_.store(index_enable, std::memory_order_release);

        update_scale();
        double min_speed = min_speed_estimate;
        if (min_speed == 0.0) min_speed = 1.0;

        if (reset) {
            // counts = raw_count - index_count, so making them equal zeroes counts and position.
            raw_count_ = low_of(count_event_.load(std::memory_order_acquire));
            index_count_ = raw_count_;
        }
        const std::uint32_t now = timebase_.load(std::memory_order_acquire);
        estimate_velocity(now, min_speed);

        const std::int32_t net = wrapping_sub(raw_count_, index_count_);
        counts = net;
        const double pos = net * scale_;
        position = pos;
        position_interpolated = pos + velocity_ * (now - timestamp_) * 1e-9;
        const std::int32_t latched = wrapping_sub(latch_count_, index_count_);
        counts_latched = latched;
        position_latched = latched * scale_;
        velocity = velocity_;
        velocity_rpm = velocity_ * 60.0;
    }

  private:
    bool missing_teeth_gap(std::uint32_t now) noexcept {
        const std::int32_t teeth = missing_teeth;
        const std::uint32_t interval = now - last_edge_ns_;
        const bool had_edge = have_edge_;
        last_edge_ns_ = now;
        have_edge_ = true;
        if (teeth <= 0 || !had_edge) return false;
        if (normal_interval_ns_ != 0 &&
            2.0 * interval > (teeth + 2.0) * static_cast<double>(normal_interval_ns_)) {
            raw_ = wrapping_add(raw_, teeth);
            normal_interval_ns_ = interval / static_cast<std::uint32_t>(teeth + 1);
            return true;
        }
        normal_interval_ns_ = interval;
        return false;
    }

    void update_scale() noexcept {
        double s = position_scale;
        if (s == old_scale_) return;
        if (s < 1e-20 && s > -1e-20) {
            // A zero scale would divide by zero; LinuxCNC repairs the pin to 1.
            s = 1.0;
            position_scale = s;
        }
        old_scale_ = s;
        scale_ = 1.0 / s;
    }

    void estimate_velocity(std::uint32_t now, double min_speed) noexcept {
        const std::uint64_t event = count_event_.load(std::memory_order_acquire);
        if (event != seen_count_event_) {
            seen_count_event_ = event;
            const std::int32_t delta_counts = wrapping_sub(low_of(event), raw_count_);
            const std::uint32_t delta_time = high_of(event) - timestamp_;
            raw_count_ = low_of(event);
            timestamp_ = high_of(event);
            if (counts_since_timeout_ < 2) {
                ++counts_since_timeout_;
            } else if (delta_time != 0) {
                velocity_ = delta_counts * scale_ / (delta_time * 1e-9);
            }
            return;
        }
        if (counts_since_timeout_ == 0) {
            velocity_ = 0.0;
            return;
        }
        const std::uint32_t since = now - timestamp_;
        if (since != 0 && since < 1e9 / std::fabs(min_speed * scale_)) {
            // No count yet: the speed cannot be above one count in `since`, keep the sign.
            const double bound = std::fabs(scale_ / (since * 1e-9));
            if (bound < velocity_) velocity_ = bound;
            if (-bound > velocity_) velocity_ = -bound;
        } else if (since != 0) {
            counts_since_timeout_ = 0;
            velocity_ = 0.0;
        }
    }

    // Written by update-counters only.
    std::uint8_t state_ = 0;
    std::int32_t raw_ = 0;
    bool old_z_ = false;
    bool old_latch_ = false;
    bool have_edge_ = false;
    std::uint32_t last_edge_ns_ = 0;
    std::uint32_t normal_interval_ns_ = 0;
    std::uint32_t index_seq_ = 0;
    std::uint32_t latch_seq_ = 0;

    // Handed from update-counters to capture-position.
    std::atomic<std::uint32_t> timebase_{0};     // ns, wraps; differences stay right
    std::atomic<std::uint64_t> count_event_{0};  // (time stamp, raw count) of the last count
    std::atomic<std::uint64_t> index_event_{0};  // (sequence, raw count at the index)
    std::atomic<std::uint64_t> latch_event_{0};  // (sequence, raw count at the latch edge)
    std::atomic<bool> index_armed_{false};       // set by capture from index-enable

    // Written by capture-position only.
    std::uint64_t seen_count_event_ = 0;
    std::uint32_t seen_index_seq_ = 0;
    std::uint32_t seen_latch_seq_ = 0;
    std::int32_t raw_count_ = 0;
    std::uint32_t timestamp_ = 0;
    std::int32_t index_count_ = 0;
    std::int32_t latch_count_ = 0;
    double old_scale_ = 1.0;
    double scale_ = 1.0;
    double velocity_ = 0.0;
    int counts_since_timeout_ = 0;
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(encoder, Encoder, "software counting of quadrature encoder signals",
                           (hal::ComponentOptions{.default_count = 3}))
