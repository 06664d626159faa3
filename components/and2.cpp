// and2: two-input AND gate, LinuxCNC-compatible (`loadrt and2`, function and2.N).
#include "hal/component.hpp"

namespace {

struct And2 : hal::Instance {
    hal::In<bool> in0{this, "in0"};
    hal::In<bool> in1{this, "in1"};
    hal::Out<bool> out{this, "out"};

    // LinuxCNC exports the logic gates as integer-only functions; `show funct` says so.
    And2() { function<&And2::update>("", false); }
    void update(hal::Period) noexcept { out = in0 && in1; }
};

}  // namespace

HAL_COMPONENT(and2, And2, "Two-input AND gate")
