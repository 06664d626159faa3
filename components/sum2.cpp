// sum2: weighted sum of two inputs plus an offset, LinuxCNC-compatible (`loadrt sum2`).
#include "hal/component.hpp"

namespace {

struct Sum2 : hal::Instance {
    hal::In<double> in0{this, "in0"};
    hal::In<double> in1{this, "in1"};
    hal::Out<double> out{this, "out"};
    hal::Param<double> gain0{this, "gain0", 1.0};
    hal::Param<double> gain1{this, "gain1", 1.0};
    hal::Param<double> offset{this, "offset", 0.0};

    void update(hal::Period) noexcept { out = in0 * gain0 + in1 * gain1 + offset; }
};

}  // namespace

HAL_COMPONENT(sum2, Sum2, "Sum of two inputs (each with a gain) and an offset")
