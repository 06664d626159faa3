// toggle: push-on/push-off from a momentary button, LinuxCNC-compatible (`loadrt toggle`,
// function toggle.N, no floating point). The press must last `debounce` periods before the
// output flips, and the release as long before the next press counts.
#include <cstdint>

#include "hal/component.hpp"

namespace {

struct Toggle : hal::Instance {
    hal::In<bool> in{this, "in"};
    hal::IO<bool> out{this, "out"};
    hal::Param<std::uint32_t> debounce{this, "debounce", 2};

    Toggle() { function<&Toggle::update>("", false); }

    void update(hal::Period) noexcept {
        // Out-of-range delays are reset rather than obeyed: a huge value would look like a dead
        // button, zero would let contact bounce toggle the output.
        if (debounce < 1 || debounce > 10000) debounce = 2;
        const std::int32_t delay = static_cast<std::int32_t>(debounce.get());
        if (in) {
            if (++counter_ >= delay) {
                counter_ = delay;
                if (!pressed_) out = !out;
                pressed_ = true;
            }
        } else if (--counter_ <= 0) {
            counter_ = 0;
            pressed_ = false;
        }
    }

  private:
    std::int32_t counter_ = 0;
    bool pressed_ = false;  // debounced button state
};

}  // namespace

HAL_COMPONENT(toggle, Toggle, "'push-on, push-off' from momentary pushbuttons")
