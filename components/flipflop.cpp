// flipflop: D flip-flop with asynchronous set and reset, LinuxCNC-compatible (`loadrt
// flipflop`, function flipflop.N, no floating point). reset wins over set; both win over clk.
#include "hal/component.hpp"

namespace {

struct Flipflop : hal::Instance {
    hal::In<bool> data{this, "data"};
    hal::In<bool> clk{this, "clk"};
    hal::In<bool> set{this, "set"};
    hal::In<bool> reset{this, "reset"};
    hal::IO<bool> out{this, "out"};
    hal::IO<bool> out_not{this, "out-not"};

    Flipflop() { function<&Flipflop::update>("", false); }

    void update(hal::Period) noexcept {
        const bool clock = clk;
        if (reset) {
            out = false;
        } else if (set) {
            out = true;
        } else if (clock && !old_clk_) {
            out = data.get();
        }
        out_not = !out;
        old_clk_ = clock;
    }

  private:
    bool old_clk_ = false;
};

}  // namespace

HAL_COMPONENT(flipflop, Flipflop, "D type flip-flop")
