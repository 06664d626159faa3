// oneshot: a pulse of `width` seconds from an input edge, LinuxCNC-compatible (`loadrt
// oneshot`, function oneshot.N). The pulse is timed in whole nanoseconds so that a width that
// is a multiple of the thread period lasts exactly that many periods (a float countdown can
// leave a 1e-18 s remainder and stretch the pulse by one period).
#include <cmath>
#include <cstdint>

#include "hal/component.hpp"

namespace {

std::int64_t seconds_to_ns(double seconds) noexcept {
    if (!(seconds > 0.0)) return 0;  // also catches NaN
    if (seconds > 9.2e9) return INT64_MAX;
    return std::llround(seconds * 1e9);
}

struct Oneshot : hal::Instance {
    hal::In<bool> in{this, "in"};
    hal::In<bool> reset{this, "reset"};
    hal::Out<bool> out{this, "out"};
    hal::Out<bool> out_not{this, "out-not"};
    hal::In<double> width{this, "width", 0.0};
    hal::Out<double> time_left{this, "time-left"};
    hal::Param<bool> retriggerable{this, "retriggerable", true};
    hal::Param<bool> rising{this, "rising", true};
    hal::Param<bool> falling{this, "falling", false};

    void update(hal::Period period) noexcept {
        if (reset) {
            left_ns_ = 0;
            old_in_ = false;
            drive();
            return;
        }
        const bool now = in;
        bool trigger = (now && !old_in_ && rising) || (!now && old_in_ && falling);
        old_in_ = now;
        if (left_ns_ > 0) {
            if (!retriggerable) trigger = false;
            left_ns_ = left_ns_ > period.ns ? left_ns_ - period.ns : 0;
        }
        if (trigger) left_ns_ = seconds_to_ns(width);
        drive();
    }

  private:
    void drive() noexcept {
        time_left = static_cast<double>(left_ns_) * 1e-9;
        out = left_ns_ > 0;
        out_not = left_ns_ <= 0;
    }

    std::int64_t left_ns_ = 0;
    bool old_in_ = false;
};

}  // namespace

HAL_COMPONENT(oneshot, Oneshot, "one-shot pulse generator")
