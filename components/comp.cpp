// comp: two-input comparator with hysteresis, LinuxCNC-compatible (`loadrt comp`).
// Within hyst/2 of equality `out` keeps its previous state and `equal` is TRUE.
#include "hal/component.hpp"

namespace {

struct Comp : hal::Instance {
    hal::In<double> in0{this, "in0"};
    hal::In<double> in1{this, "in1"};
    hal::Out<bool> out{this, "out"};
    hal::Out<bool> equal{this, "equal"};
    hal::Param<double> hyst{this, "hyst", 0.0};

    void update(hal::Period) noexcept {
        const double difference = in1 - in0;
        const double half_band = 0.5 * hyst;
        if (difference < -half_band) {
            state_ = false;
            equal = false;
        } else if (difference > half_band) {
            state_ = true;
            equal = false;
        } else {
            equal = true;
        }
        out = state_;
    }

  private:
    bool state_ = false;
};

}  // namespace

HAL_COMPONENT(comp, Comp, "Two input comparator with hysteresis")
