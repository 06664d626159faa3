// near: TRUE when two values are within a ratio or an absolute difference of each other,
// LinuxCNC-compatible (`loadrt near`, function near.N).
#include <cmath>

#include "hal/component.hpp"

namespace {

struct Near : hal::Instance {
    hal::In<double> in1{this, "in1"};
    hal::In<double> in2{this, "in2"};
    hal::Out<bool> out{this, "out"};
    hal::Param<double> scale{this, "scale", 1.0};
    hal::Param<double> difference{this, "difference", 0.0};

    void update(hal::Period) noexcept {
        double a = in1, b = in2;
        // The ratio test is written for a positive in1; mirroring both keeps it symmetric.
        if (a < 0) {
            a = -a;
            b = -b;
        }
        const double ratio = scale;
        const bool within_ratio = ratio > 1 && a / ratio <= b && b <= a * ratio;
        out = within_ratio || std::fabs(a - b) <= difference;
    }
};

}  // namespace

HAL_COMPONENT(near, Near, "Determine whether two values are roughly equal")
