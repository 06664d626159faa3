// mux2: two-way selector for floats, LinuxCNC-compatible (`loadrt mux2`, function mux2.N).
#include "hal/component.hpp"

namespace {

struct Mux2 : hal::Instance {
    hal::In<bool> sel{this, "sel"};
    hal::Out<double> out{this, "out"};
    hal::In<double> in1{this, "in1"};
    hal::In<double> in0{this, "in0"};

    void update(hal::Period) noexcept { out = sel ? in1.get() : in0.get(); }
};

}  // namespace

HAL_COMPONENT(mux2, Mux2, "Select from one of two input values")
