// streamer: writes records from a stream to a set of pins, one record per call (or per clock
// edge), for halstreamer to feed from a file; LinuxCNC-compatible (`loadrt streamer
// depth=D[,D...] cfg=LETTERS[,LETTERS...]`, one instance streamer.N with function streamer.N
// per cfg item).
//
// cfg has one letter per pin: b bit, f float, s s32, u u32 (as LinuxCNC), plus l s64 and
// k u64; upper case is accepted too. Column M of each record goes to pin streamer.N.pin.M.
// The stream is named after the instance ("streamer.0") and written by a userspace client
// (halstreamer) through the client library.
//
// clock-mode: 0 take a record every call (default), 1 on a falling edge of clock, 2 on a
// rising edge, 3 on either edge; other values behave as 0. A record wanted while the stream
// is empty counts an underrun and leaves the pins unchanged. enable FALSE pauses everything,
// clock edge detection included. curr-depth is the number of records waiting at the start of
// the call; empty is TRUE when there were none. underruns is an I/O pin so that setp can reset it,
// as in LinuxCNC.
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "hal/component.hpp"

namespace {

std::string streamer_layout(const hal::Instance& self) {
    auto cfg = self.arg("cfg");
    if (!cfg || cfg->empty())
        throw hal::Error(
            "cfg=LETTERS[,LETTERS...] is required: one letter per pin "
            "(b bit, f float, s s32, u u32, l s64, k u64)");
    return *cfg;
}

std::uint32_t streamer_depth(const hal::Instance& self) {
    const long depth = self.arg_int("depth", 0);
    if (depth < 1 || depth > (1L << 24))
        throw hal::Error("depth=N (records, 1 to 16777216) is required for " +
                         std::string(self.name()));
    return static_cast<std::uint32_t>(depth);
}

using StreamedPin =
    std::variant<std::unique_ptr<hal::Out<bool>>, std::unique_ptr<hal::Out<double>>,
                 std::unique_ptr<hal::Out<std::int32_t>>, std::unique_ptr<hal::Out<std::uint32_t>>,
                 std::unique_ptr<hal::Out<std::int64_t>>, std::unique_ptr<hal::Out<std::uint64_t>>>;

template <class T>
StreamedPin make_pin(hal::Instance* owner, const std::string& name) {
    return std::make_unique<hal::Out<T>>(owner, name);
}

StreamedPin make_streamed_pin(hal::Instance* owner, hal::Type type, std::size_t column) {
    const std::string name = "pin." + std::to_string(column);
    switch (type) {
        case hal::Type::Bit:
            return make_pin<bool>(owner, name);
        case hal::Type::Float:
            return make_pin<double>(owner, name);
        case hal::Type::S32:
            return make_pin<std::int32_t>(owner, name);
        case hal::Type::U32:
            return make_pin<std::uint32_t>(owner, name);
        case hal::Type::S64:
            return make_pin<std::int64_t>(owner, name);
        case hal::Type::U64:
            return make_pin<std::uint64_t>(owner, name);
    }
    throw hal::Error("unknown field type");
}

template <class T>
T value_as(const hal::Value& v) noexcept {
    if constexpr (std::is_same_v<T, bool>)
        return v.b;
    else if constexpr (std::is_same_v<T, double>)
        return v.f;
    else if constexpr (std::is_same_v<T, std::int32_t>)
        return v.s32;
    else if constexpr (std::is_same_v<T, std::uint32_t>)
        return v.u32;
    else if constexpr (std::is_same_v<T, std::int64_t>)
        return v.s64;
    else
        return v.u64;
}

template <class T>
void write_pin(std::unique_ptr<hal::Out<T>>& pin, const hal::Value& v) noexcept {
    pin->set(value_as<T>(v));
}

struct Streamer : hal::Instance {
    hal::Stream stream{this, name(), streamer_layout(*this), streamer_depth(*this)};
    hal::Out<bool> empty{this, "empty", true};
    hal::In<bool> enable{this, "enable", true};
    hal::Out<std::int32_t> curr_depth{this, "curr-depth"};
    hal::IO<std::int32_t> underruns{this, "underruns"};
    hal::In<bool> clock{this, "clock"};
    hal::In<std::int32_t> clock_mode{this, "clock-mode"};

    Streamer() : record_(stream.fields()) {
        for (std::size_t i = 0; i < stream.fields(); ++i)
            pins_.push_back(make_streamed_pin(this, stream.field_type(i), i));
        // Like LinuxCNC, the function needs a floating-point thread only if a float is moved.
        bool moves_float = false;
        for (std::size_t i = 0; i < stream.fields(); ++i)
            moves_float = moves_float || stream.field_type(i) == hal::Type::Float;
        function<&Streamer::update>("", moves_float);
    }

    void update(hal::Period) noexcept {
        // Like LinuxCNC 2.9, curr-depth and empty describe the stream as this call found it,
        // before taking a record: the call that takes the last record still shows 1 / FALSE.
        const std::uint32_t used = stream.used();
        curr_depth = static_cast<std::int32_t>(used);
        empty = used == 0;
        if (enable && clocked()) {
            if (stream.pop(record_.data())) {
                for (std::size_t i = 0; i < pins_.size(); ++i)
                    std::visit([&](auto& pin) { write_pin(pin, record_[i]); }, pins_[i]);
            } else {
                underruns = underruns + 1;
            }
        }
    }

  private:
    // Whether this call should take a record; keeps the last two clock samples.
    bool clocked() noexcept {
        clock_history_ = ((clock_history_ << 1) | (clock ? 1 : 0)) & 3;
        switch (clock_mode) {
            case 1:
                return clock_history_ == 2;  // was high, now low
            case 2:
                return clock_history_ == 1;  // was low, now high
            case 3:
                return clock_history_ == 1 || clock_history_ == 2;
            default:
                return true;
        }
    }

    std::vector<StreamedPin> pins_;
    std::vector<hal::Value> record_;  // sized once here; the realtime path never allocates
    unsigned clock_history_ = 0;
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(streamer, Streamer, "stream file data into HAL in real time",
                           (hal::ComponentOptions{.count_from = "cfg"}), "cfg", "depth")
