// limit1: clamps a float between min and max, LinuxCNC-compatible (`loadrt limit1`).
// When min > max, max wins (it is applied last), as in LinuxCNC.
#include "hal/component.hpp"

namespace {

struct Limit1 : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};
    hal::In<double> min{this, "min", -1e20};
    hal::In<double> max{this, "max", 1e20};

    void update(hal::Period) noexcept {
        double value = in;
        if (value < min) value = min;
        if (value > max) value = max;
        out = value;
    }
};

}  // namespace

HAL_COMPONENT(limit1, Limit1, "Limit the output signal to fall between min and max")
