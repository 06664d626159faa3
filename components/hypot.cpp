// hypot: Euclidean length of up to three inputs, LinuxCNC-compatible (`loadrt hypot
// names=vel_xy,vel_xyz`, function named after the instance). LinuxCNC's sim configs use it for
// the XY and XYZ path speed from per-axis velocities.
#include <cmath>

#include "hal/component.hpp"

namespace {

struct Hypot : hal::Instance {
    hal::In<double> in0{this, "in0"};
    hal::In<double> in1{this, "in1"};
    hal::In<double> in2{this, "in2"};
    hal::Out<double> out{this, "out"};

    // std::hypot rather than sqrt of the sum of squares: the same value for ordinary inputs,
    // but no overflow to inf for |in| above 1e154.
    void update(hal::Period) noexcept { out = std::hypot(in0.get(), in1.get(), in2.get()); }
};

}  // namespace

HAL_COMPONENT(hypot, Hypot, "Euclidean length sqrt(in0^2 + in1^2 + in2^2)")
