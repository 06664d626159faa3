// lowpass: first-order low-pass filter out += (in - out) * gain, LinuxCNC-compatible
// (`loadrt lowpass`). gain = 1 - exp(-2*pi*f_hz*period_s) places the pole at f_hz.
#include "hal/component.hpp"

namespace {

struct Lowpass : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};
    hal::In<bool> load{this, "load"};
    hal::Param<double> gain{this, "gain", 0.0};

    void update(hal::Period) noexcept {
        const double value = in;
        state_ = load ? value : state_ + (value - state_) * gain;
        out = state_;
    }

  private:
    double state_ = 0.0;
};

}  // namespace

HAL_COMPONENT(lowpass, Lowpass, "Low-pass filter")
