// or2: two-input OR gate, LinuxCNC-compatible (`loadrt or2`, function or2.N).
#include "hal/component.hpp"

namespace {

struct Or2 : hal::Instance {
    hal::In<bool> in0{this, "in0"};
    hal::In<bool> in1{this, "in1"};
    hal::Out<bool> out{this, "out"};

    Or2() { function<&Or2::update>("", false); }
    void update(hal::Period) noexcept { out = in0 || in1; }
};

}  // namespace

HAL_COMPONENT(or2, Or2, "Two-input OR gate")
