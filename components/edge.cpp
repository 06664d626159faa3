// edge: turns a chosen edge of a bit input into a pulse of out-width-ns, LinuxCNC-compatible
// (`loadrt edge`, function edge.N, no floating point). The pulse is timed in whole
// nanoseconds from the Period argument, so it can run in a fast base thread.
#include <cstdint>

#include "hal/component.hpp"

namespace {

struct Edge : hal::Instance {
    hal::In<bool> in{this, "in"};
    hal::Out<bool> out{this, "out"};
    hal::Out<bool> out_invert{this, "out-invert"};
    hal::Param<bool> both{this, "both", false};
    hal::Param<bool> in_edge{this, "in-edge", true};  // TRUE selects the falling edge
    hal::Param<std::int32_t> out_width_ns{this, "out-width-ns", 0};
    hal::Param<std::int32_t> time_left_ns{this, "time-left-ns", 0, hal::ParamDir::RO};
    hal::Param<bool> last_in{this, "last-in", false, hal::ParamDir::RO};

    Edge() { function<&Edge::update>("", false); }

    void update(hal::Period period) noexcept {
        const bool now = in;
        const bool before = last_in;
        const bool rise = now && !before;
        const bool fall = !now && before;
        const bool wanted = both ? (rise || fall) : (in_edge ? fall : rise);
        bool pulse;
        if (wanted) {
            time_left_ns = out_width_ns.get();
            pulse = true;
        } else if (time_left_ns > 0) {
            // The period just run is spent: the pulse continues only if time is still left, so
            // it lasts ceil(out-width-ns / period) runs, at least one (measured on LinuxCNC 2.9).
            const std::int64_t left = std::int64_t{time_left_ns} - period.ns;
            pulse = left > 0;
            time_left_ns = pulse ? static_cast<std::int32_t>(left) : 0;
        } else {
            time_left_ns = 0;
            pulse = false;
        }
        out = pulse;
        out_invert = !pulse;
        last_in = now;
    }
};

}  // namespace

HAL_COMPONENT(edge, Edge, "Edge detector")
