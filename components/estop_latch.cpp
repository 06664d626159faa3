// estop_latch: the software part of an e-stop chain, LinuxCNC-compatible (`loadrt
// estop_latch`, function estop-latch.N, no floating point). Starts faulted; only a rising edge
// on reset while no fault is present makes it OK; any fault trips it again at once.
#include "hal/component.hpp"

namespace {

struct EstopLatch : hal::Instance {
    // Unconnected inputs default to "no fault" so a single fault source can be wired alone.
    hal::In<bool> ok_in{this, "ok-in", true};
    hal::In<bool> fault_in{this, "fault-in", false};
    hal::In<bool> reset{this, "reset"};
    hal::Out<bool> ok_out{this, "ok-out", false};
    hal::Out<bool> fault_out{this, "fault-out", true};
    hal::Out<bool> watchdog{this, "watchdog"};

    EstopLatch() { function<&EstopLatch::update>("", false); }

    void update(hal::Period) noexcept {
        const bool reset_now = reset;
        if (ok_in && !fault_in) {
            if (reset_now && !old_reset_) ok_ = true;
            // A toggling watchdog proves to an external charge pump that this thread runs.
            if (ok_) watchdog_ = !watchdog_;
        } else {
            ok_ = false;
        }
        ok_out = ok_;
        fault_out = !ok_;
        watchdog = watchdog_;
        old_reset_ = reset_now;
    }

  private:
    bool ok_ = false;
    bool watchdog_ = false;
    bool old_reset_ = false;
};

}  // namespace

HAL_COMPONENT(estop_latch, EstopLatch, "Software ESTOP latch")
