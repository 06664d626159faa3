// timedelta: LinuxCNC's scheduling-jitter probe (`loadrt timedelta`, function timedelta.N,
// no floating point), with one deliberate difference: it never reads a clock. Only the thread
// runner may read time (so simulated-clock runs are reproducible), so "now" here is the sum of
// the Period arguments this function has received. Under the simulated clock every figure is
// therefore exact and the jitter is 0; on a real thread the runner passes the nominal period
// too, so the real wake-up jitter is in the thread's own timing (`show thread`), not here.
#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include "hal/component.hpp"

namespace {

std::int32_t saturate_s32(std::int64_t v) noexcept {
    return static_cast<std::int32_t>(std::clamp<std::int64_t>(v, INT32_MIN, INT32_MAX));
}

struct Timedelta : hal::Instance {
    hal::Out<std::int32_t> out{this, "out"};
    hal::Out<std::int32_t> err{this, "err", 0};
    hal::Out<std::int32_t> min{this, "min", 0};
    hal::Out<std::int32_t> max{this, "max", 0};
    hal::Out<std::int32_t> jitter{this, "jitter", 0};
    hal::Out<std::int32_t> current_jitter{this, "current-jitter", 0};
    hal::Out<std::int32_t> current_error{this, "current-error", 0};
    hal::Out<double> avg_err{this, "avg-err", 0.0};
    hal::In<bool> reset{this, "reset"};

    Timedelta() { function<&Timedelta::update>("", false); }

    void update(hal::Period period) noexcept {
        now_ns_ += period.ns;
        if (have_last_) measure(now_ns_ - last_ns_, period.ns);
        if (reset) {
            // Restart min/max/jitter from the next pair of runs; err and avg-err keep going.
            have_last_ = false;
            first_ = true;
        } else {
            have_last_ = true;
            last_ns_ = now_ns_;
        }
    }

  private:
    void measure(std::int64_t delta_ns, std::int64_t period_ns) noexcept {
        out = saturate_s32(delta_ns);
        const std::int64_t error_ns = delta_ns - period_ns;
        current_error = saturate_s32(error_ns);
        current_jitter = saturate_s32(std::llabs(error_ns));
        err_ns_ += error_ns;
        err = saturate_s32(err_ns_);
        if (first_) {
            first_ = false;
            min_ns_ = max_ns_ = delta_ns;
        } else {
            min_ns_ = std::min(min_ns_, delta_ns);
            max_ns_ = std::max(max_ns_, delta_ns);
        }
        min = saturate_s32(min_ns_);
        max = saturate_s32(max_ns_);
        jitter = saturate_s32(std::max(max_ns_ - period_ns, period_ns - min_ns_));
        ++count_;
        avg_err = static_cast<double>(err_ns_) / static_cast<double>(count_);
    }

    std::int64_t now_ns_ = 0;
    std::int64_t last_ns_ = 0;
    std::int64_t err_ns_ = 0;
    std::int64_t min_ns_ = 0;
    std::int64_t max_ns_ = 0;
    std::int64_t count_ = 0;
    bool have_last_ = false;
    bool first_ = true;
};

}  // namespace

HAL_COMPONENT(timedelta, Timedelta,
              "LinuxCNC HAL component that measures thread scheduling timing behavior")
