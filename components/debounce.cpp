// debounce: groups of bit filters that share one delay, LinuxCNC-compatible (`loadrt debounce
// cfg=size[,size...]`): each cfg item is one group debounce.G with filters debounce.G.F, a
// `delay` parameter and a function debounce.G (no floating point).
//
// Each filter counts up (to delay) while its input is TRUE and down (to 0) while it is FALSE;
// the output turns TRUE when the count is already at delay and the input is still TRUE, and
// FALSE when the count is already at 0 and the input is still FALSE. So a change must be seen
// on delay+1 consecutive samples before the output follows; delay 0 passes the input through.
#include <cstdint>
#include <memory>

#include "hal/component.hpp"

namespace {

constexpr long kMaxFilters = 1000;

std::size_t group_size(const hal::Instance& self) {
    if (!self.arg("cfg"))
        throw hal::Error("cfg=size[,size...] is required: one filter count per group");
    const long size = self.arg_int("cfg", 0);
    if (size < 1 || size > kMaxFilters)
        throw hal::Error("cfg=" + std::to_string(size) + " for group " + std::string(self.name()) +
                         ": a group has 1 to " + std::to_string(kMaxFilters) + " filters");
    return static_cast<std::size_t>(size);
}

struct Debounce : hal::Instance {
    std::size_t filters = group_size(*this);
    hal::Array<hal::In<bool>> in{this, "{}.in", filters};
    hal::Array<hal::Out<bool>> out{this, "{}.out", filters};
    hal::Param<std::int32_t> delay{this, "delay", 5};

    Debounce() : count_(new std::int32_t[filters]()), state_(new bool[filters]()) {
        function<&Debounce::update>("", false);
    }

    void update(hal::Period) noexcept {
        if (delay < 0) delay = 1;  // a negative delay is a typo; LinuxCNC repairs it to 1
        const std::int32_t limit = delay;
        for (std::size_t i = 0; i < filters; ++i) {
            if (in[i]) {
                if (count_[i] < limit) {
                    ++count_[i];
                } else {
                    state_[i] = true;
                }
            } else if (count_[i] > 0) {
                --count_[i];
            } else {
                state_[i] = false;
            }
            out[i] = state_[i];
        }
    }

  private:
    std::unique_ptr<std::int32_t[]> count_;
    std::unique_ptr<bool[]> state_;  // out pins cannot be read back
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(debounce, Debounce, "filter noisy digital inputs",
                           (hal::ComponentOptions{.count_from = "cfg"}), "cfg")
