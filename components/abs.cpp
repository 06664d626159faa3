// abs: absolute value and sign of a float, LinuxCNC-compatible (`loadrt abs`, function abs.N).
#include "hal/component.hpp"

namespace {

// LinuxCNC treats inputs within one millionth of zero as neither positive nor negative, so
// is-positive/is-negative do not chatter on noise around zero; sign has no such band.
constexpr double kZeroBand = 0.000001;

struct Abs : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};
    hal::Out<bool> sign{this, "sign"};
    hal::Out<bool> is_positive{this, "is-positive"};
    hal::Out<bool> is_negative{this, "is-negative"};

    void update(hal::Period) noexcept {
        const double value = in;
        const bool negative = !(value >= 0.0);
        sign = negative;
        out = negative ? -value : value;
        is_positive = value > kZeroBand;
        is_negative = value < -kZeroBand;
    }
};

}  // namespace

HAL_COMPONENT(abs, Abs, "Compute the absolute value and sign of the input signal")
