// scale: out = in * gain + offset, LinuxCNC-compatible (`loadrt scale`, function scale.N).
// gain and offset are input pins (not params), so they can be driven by signals.
#include "hal/component.hpp"

namespace {

struct Scale : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::In<double> gain{this, "gain"};
    hal::In<double> offset{this, "offset"};
    hal::Out<double> out{this, "out"};

    void update(hal::Period) noexcept { out = in * gain + offset; }
};

}  // namespace

HAL_COMPONENT(scale, Scale, "Applies a scale and offset to its input")
