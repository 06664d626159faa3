// div2: quotient of two inputs, LinuxCNC 2.9-compatible (`loadrt div2`, function div2.N).
//
// Like LinuxCNC 2.9, a divisor closer to zero than `deadband` is replaced by +deadband or
// -deadband (keeping its side of zero; an exact zero counts as positive), so the output stays
// finite and keeps its sign. deadband itself is raised to 1e-12 whenever it is set lower,
// which is why a division by exactly zero still gives a finite, very large number.
#include "hal/component.hpp"

namespace {

constexpr double kMinDeadband = 1e-12;

struct Div2 : hal::Instance {
    hal::In<double> in0{this, "in0"};
    hal::In<double> in1{this, "in1"};
    hal::Out<double> out{this, "out"};
    hal::Param<double> deadband{this, "deadband", 0.0};

    void update(hal::Period) noexcept {
        if (!(deadband >= kMinDeadband)) deadband = kMinDeadband;
        const double band = deadband;
        const double divisor = in1;
        if (divisor > -band && divisor < 0.0) {
            out = in0 / -band;
        } else if (divisor >= 0.0 && divisor < band) {
            out = in0 / band;
        } else {
            out = in0 / divisor;
        }
    }
};

}  // namespace

HAL_COMPONENT(div2, Div2, "Quotient of two floating point inputs")
