// integ: integrator with gain and windup limits, LinuxCNC 2.9-compatible (`loadrt integ`).
// Each cycle adds gain*in*period (rectangle rule) and then clamps to [min, max], max first.
#include "hal/component.hpp"

namespace {

struct Integ : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::In<double> gain{this, "gain", 1.0};
    hal::Out<double> out{this, "out"};
    hal::In<bool> reset{this, "reset"};
    hal::In<double> max{this, "max", 1e20};
    hal::In<double> min{this, "min", -1e20};

    void update(hal::Period period) noexcept {
        double sum = reset ? 0.0 : sum_ + gain * in * period.s;
        if (sum > max) sum = max;
        if (sum < min) sum = min;
        sum_ = sum;
        out = sum;
    }

  private:
    double sum_ = 0.0;
};

}  // namespace

HAL_COMPONENT(integ, Integ, "Integrator with gain pin and windup limits")
