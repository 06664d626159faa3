// xor2: two-input exclusive-OR gate, LinuxCNC-compatible (`loadrt xor2`, function xor2.N).
#include "hal/component.hpp"

namespace {

struct Xor2 : hal::Instance {
    hal::In<bool> in0{this, "in0"};
    hal::In<bool> in1{this, "in1"};
    hal::Out<bool> out{this, "out"};

    Xor2() { function<&Xor2::update>("", false); }
    void update(hal::Period) noexcept { out = in0.get() != in1.get(); }
};

}  // namespace

HAL_COMPONENT(xor2, Xor2, "Two-input XOR (exclusive OR) gate")
