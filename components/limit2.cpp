// limit2: clamps a float between min and max and limits its rate of change to maxv per
// second, LinuxCNC-compatible (`loadrt limit2`, function limit2.N). The output starts at 0,
// so the first cycles ramp from 0 unless `load` is TRUE.
#include "hal/component.hpp"

namespace {

double clamp_low_first(double value, double low, double high) noexcept {
    if (value < low) return low;
    if (value > high) return high;
    return value;
}

struct Limit2 : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};
    hal::In<bool> load{this, "load"};
    hal::In<double> min{this, "min", -1e20};
    hal::In<double> max{this, "max", 1e20};
    hal::In<double> maxv{this, "maxv", 1e20};

    void update(hal::Period period) noexcept {
        double target = clamp_low_first(in, min, max);
        if (!load) {
            const double max_step = maxv * period.s;
            target = clamp_low_first(target, last_out_ - max_step, last_out_ + max_step);
        }
        last_out_ = target;
        out = target;
    }

  private:
    double last_out_ = 0.0;  // an Out pin cannot be read back
};

}  // namespace

HAL_COMPONENT(limit2, Limit2,
              "Limit the output signal to fall between min and max and limit its slew rate to "
              "less than maxv per second")
