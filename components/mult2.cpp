// mult2: product of two inputs, LinuxCNC-compatible (`loadrt mult2`, function mult2.N).
#include "hal/component.hpp"

namespace {

struct Mult2 : hal::Instance {
    hal::In<double> in0{this, "in0"};
    hal::In<double> in1{this, "in1"};
    hal::Out<double> out{this, "out"};

    void update(hal::Period) noexcept { out = in0 * in1; }
};

}  // namespace

HAL_COMPONENT(mult2, Mult2, "Product of two inputs")
