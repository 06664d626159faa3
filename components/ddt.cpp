// ddt: derivative of the input by backward difference, LinuxCNC-compatible (`loadrt ddt`).
// The previous input starts at 0, so the first cycle reports in/period, as LinuxCNC does.
#include "hal/component.hpp"

namespace {

struct Ddt : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};

    void update(hal::Period period) noexcept {
        const double value = in;
        out = (value - previous_) / period.s;
        previous_ = value;
    }

  private:
    double previous_ = 0.0;
};

}  // namespace

HAL_COMPONENT(ddt, Ddt, "Compute the derivative of the input function")
