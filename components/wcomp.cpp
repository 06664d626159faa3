// wcomp: window comparator, LinuxCNC-compatible (`loadrt wcomp`, function wcomp.N).
#include "hal/component.hpp"

namespace {

struct Wcomp : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::In<double> min{this, "min"};
    hal::In<double> max{this, "max"};
    hal::Out<bool> out{this, "out"};
    hal::Out<bool> under{this, "under"};
    hal::Out<bool> over{this, "over"};

    void update(hal::Period) noexcept {
        const double value = in, low = min, high = max;
        out = low < value && value < high;
        under = value <= low;
        over = value >= high;
    }
};

}  // namespace

HAL_COMPONENT(wcomp, Wcomp, "Window comparator")
