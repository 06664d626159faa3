// deadzone: returns `center` while the input is within threshold/2 of it, and the input moved
// threshold/2 towards the center outside that band (so the output is continuous),
// LinuxCNC-compatible (`loadrt deadzone`, function deadzone.N).
#include "hal/component.hpp"

namespace {

struct Deadzone : hal::Instance {
    hal::Param<double> center{this, "center", 0.0};
    hal::Param<double> threshold{this, "threshold", 1.0};
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};

    void update(hal::Period) noexcept {
        const double half = threshold / 2;
        const double mid = center;
        const double value = in;
        if (value < mid - half)
            out = value + half;
        else if (value > mid + half)
            out = value - half;
        else
            out = mid;
    }
};

}  // namespace

HAL_COMPONENT(deadzone, Deadzone, "Return the center if within the threshold")
