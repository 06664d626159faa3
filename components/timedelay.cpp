// timedelay: a time-delay relay, LinuxCNC-compatible (`loadrt timedelay`, function
// timedelay.N). out follows in once in has differed from out for on-delay (rising) or
// off-delay (falling) seconds. Time is counted in whole nanoseconds from the Period argument,
// so a delay that is a multiple of the period switches exactly on that period.
#include <cmath>
#include <cstdint>

#include "hal/component.hpp"

namespace {

std::int64_t seconds_to_ns(double seconds) noexcept {
    if (!(seconds > 0.0)) return 0;  // also catches NaN
    if (seconds > 9.2e9) return INT64_MAX;
    return std::llround(seconds * 1e9);
}

struct Timedelay : hal::Instance {
    hal::In<bool> in{this, "in"};
    hal::Out<bool> out{this, "out"};
    hal::In<double> on_delay{this, "on-delay", 0.5};
    hal::In<double> off_delay{this, "off-delay", 0.5};
    hal::Out<double> elapsed{this, "elapsed"};

    void update(hal::Period period) noexcept {
        const bool now = in;
        if (now == out_) {
            timer_ns_ = 0;  // elapsed keeps showing the last delay, as LinuxCNC's does
            return;
        }
        timer_ns_ += period.ns;
        elapsed = static_cast<double>(timer_ns_) * 1e-9;
        if (timer_ns_ >= seconds_to_ns(now ? on_delay : off_delay)) {
            out_ = now;
            out = now;
            timer_ns_ = 0;
        }
    }

  private:
    std::int64_t timer_ns_ = 0;
    bool out_ = false;
};

}  // namespace

HAL_COMPONENT(timedelay, Timedelay, "The equivalent of a time-delay relay")
