// weighted_sum: sums the weights of the TRUE input bits plus an offset, LinuxCNC-compatible
// (`loadrt weighted_sum wsum_sizes=8,4`: one summer per list item, named wsum.0, wsum.1, ...,
// all updated by the one function process_wsums).
//
// LinuxCNC caps a summer at 16 bits; here it is 32, the width of the s32 sum. The default
// weights are 2^m, so bit 31 weighs -2^31 and 32 bits read as a two's-complement number.
#include <cstdint>
#include <string>

#include "hal/component.hpp"

namespace {

constexpr long kMaxBits = 32;

std::size_t summer_bits(const hal::Instance& self) {
    if (!self.arg("wsum_sizes"))
        throw hal::Error(
            "wsum_sizes= is required: the number of input bits of each summer, "
            "e.g. wsum_sizes=8,4");
    const long bits = self.arg_int("wsum_sizes", 0);
    if (bits < 1 || bits > kMaxBits)
        throw hal::Error("wsum_sizes item " + std::to_string(bits) + " for " +
                         std::string(self.name()) + " is out of range: give 1 to 32 bits");
    return static_cast<std::size_t>(bits);
}

struct WeightedSum : hal::Instance {
    hal::IO<std::int32_t> offset{this, "offset"};
    hal::Out<std::int32_t> sum{this, "sum"};
    hal::In<bool> hold{this, "hold"};
    hal::Array<hal::In<bool>> bit_in{this, "bit.{}.in", summer_bits(*this)};
    hal::Array<hal::IO<std::int32_t>> weight{this, "bit.{}.weight", bit_in.size()};

    WeightedSum() {
        for (std::size_t m = 0; m < weight.size(); ++m)
            weight[m] = static_cast<std::int32_t>(std::uint32_t{1} << m);
        shared_function<&WeightedSum::process>("=process_wsums");
    }

    void process(hal::Period) noexcept {
        if (hold) return;
        // Unsigned arithmetic so an overflowing sum wraps instead of being undefined.
        auto total = static_cast<std::uint32_t>(offset.get());
        for (std::size_t m = 0; m < bit_in.size(); ++m)
            if (bit_in[m]) total += static_cast<std::uint32_t>(weight[m].get());
        sum = static_cast<std::int32_t>(total);
    }
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(weighted_sum, WeightedSum, "Convert a group of bits to an integer",
                           (hal::ComponentOptions{.prefix = "wsum", .count_from = "wsum_sizes"}), "wsum_sizes")
