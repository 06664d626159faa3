// offset: adds an offset to a command and removes it from the matching feedback,
// LinuxCNC-compatible (`loadrt offset`, functions offset.N.update-output and
// offset.N.update-feedback). Two functions so each can sit in the thread next to the
// command producer and the feedback reader respectively.
#include "hal/component.hpp"

namespace {

struct Offset : hal::Instance {
    hal::In<double> offset{this, "offset"};
    hal::In<double> in{this, "in"};
    hal::Out<double> out{this, "out"};
    hal::In<double> fb_in{this, "fb-in"};
    hal::Out<double> fb_out{this, "fb-out"};

    Offset() {
        function<&Offset::update_output>("update-output");
        function<&Offset::update_feedback>("update-feedback");
    }
    void update_output(hal::Period) noexcept { out = in + offset; }
    void update_feedback(hal::Period) noexcept { fb_out = fb_in - offset; }
};

}  // namespace

HAL_COMPONENT(offset, Offset,
              "Adds an offset to an input, and subtracts it from the feedback value")
