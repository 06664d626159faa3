// bitslice: splits a u32 into bit outputs out-00, out-01, ..., LinuxCNC-compatible
// (`loadrt bitslice personality=N[,N...]`, one number of bits per instance, at most 32).
#include <cstdint>
#include <string>

#include "hal/component.hpp"

namespace {

constexpr long kMaxBits = 32;

std::size_t bit_count(const hal::Instance& self) {
    const long bits = self.arg_int("personality", kMaxBits);
    if (bits < 1 || bits > kMaxBits)
        throw hal::Error("personality=" + std::to_string(bits) + " for " +
                         std::string(self.name()) + " is out of range: give 1 to 32 bits");
    return static_cast<std::size_t>(bits);
}

struct Bitslice : hal::Instance {
    hal::In<std::uint32_t> in{this, "in"};
    hal::Array<hal::Out<bool>> out{this, "out-{:02}", bit_count(*this)};

    Bitslice() { function<&Bitslice::update>("", false); }
    void update(hal::Period) noexcept {
        const std::uint32_t value = in;
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = ((value >> i) & 1u) != 0;
    }
};

}  // namespace

HAL_COMPONENT(bitslice, Bitslice, "Converts an unsigned-32 input into individual bits",
              "personality")
