// sample_hold: passes an s32 through while hold is FALSE and freezes it while hold is TRUE,
// LinuxCNC-compatible (`loadrt sample_hold`, function sample-hold.N, no floating point).
#include <cstdint>

#include "hal/component.hpp"

namespace {

struct SampleHold : hal::Instance {
    hal::In<std::int32_t> in{this, "in"};
    hal::In<bool> hold{this, "hold"};
    hal::Out<std::int32_t> out{this, "out"};

    SampleHold() { function<&SampleHold::update>("", false); }

    void update(hal::Period) noexcept {
        if (!hold) out = in.get();
    }
};

}  // namespace

HAL_COMPONENT(sample_hold, SampleHold, "Sample and Hold")
