// select8: one-hot decoder of a number 0..7, LinuxCNC-compatible (`loadrt select8`).
#include <cstdint>

#include "hal/component.hpp"

namespace {

struct Select8 : hal::Instance {
    hal::In<bool> enable{this, "enable", true};
    hal::In<std::int32_t> sel{this, "sel"};
    hal::Array<hal::Out<bool>> out{this, "out{}", 8};

    Select8() { function<&Select8::update>("", false); }
    void update(hal::Period) noexcept {
        const bool on = enable;
        const std::int32_t chosen = sel;
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = on && chosen == static_cast<std::int32_t>(i);
    }
};

}  // namespace

HAL_COMPONENT(select8, Select8, "8-bit binary match detector")
