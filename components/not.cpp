// not: inverter, LinuxCNC-compatible (`loadrt not`, function not.N).
#include "hal/component.hpp"

namespace {

struct Not : hal::Instance {
    hal::In<bool> in{this, "in"};
    hal::Out<bool> out{this, "out"};

    Not() { function<&Not::update>("", false); }
    void update(hal::Period) noexcept { out = !in; }
};

}  // namespace

HAL_COMPONENT(not, Not, "Inverter")
