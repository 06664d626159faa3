// The loadrt arguments sampler and streamer share: cfg= (one type letter per field, one
// list item per instance) and depth= (records in the ring).
#pragma once

#include <string>

#include "hal/component.hpp"

namespace stream_args {

inline std::string layout(const hal::Instance& self) {
    auto cfg = self.arg("cfg");
    if (!cfg || cfg->empty())
        throw hal::Error(
            "cfg=LETTERS[,LETTERS...] is required: one letter per pin "
            "(b bit, f float, s s32, u u32, l s64, k u64)");
    return *cfg;
}

inline std::uint32_t depth(const hal::Instance& self) {
    const long depth = self.arg_int("depth", 0);
    if (depth < 1 || depth > (1L << 24))
        throw hal::Error("depth=N (records, 1 to 16777216) is required for " + std::string(self.name()));
    return static_cast<std::uint32_t>(depth);
}

// LinuxCNC's rule: the function needs a floating-point thread only if a float is moved.
inline bool moves_float(const hal::Stream& stream) {
    for (std::size_t i = 0; i < stream.fields(); ++i)
        if (stream.field_type(i) == hal::Type::Float) return true;
    return false;
}

}  // namespace stream_args
