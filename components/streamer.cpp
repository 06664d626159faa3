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
#include <vector>

#include "hal/component.hpp"
#include "stream_args.hpp"

namespace {

struct Streamer : hal::Instance {
    hal::Stream stream{this, name(), stream_args::layout(*this), stream_args::depth(*this)};
    hal::Out<bool> empty{this, "empty", true};
    hal::In<bool> enable{this, "enable", true};
    hal::Out<std::int32_t> curr_depth{this, "curr-depth"};
    hal::IO<std::int32_t> underruns{this, "underruns"};
    hal::In<bool> clock{this, "clock"};
    hal::In<std::int32_t> clock_mode{this, "clock-mode"};

    Streamer() : record_(stream.fields()) {
        for (std::size_t i = 0; i < stream.fields(); ++i)
            pins_.push_back(std::make_unique<hal::AnyPin>(this, "pin." + std::to_string(i),
                                                          stream.field_type(i), hal::Dir::Out));
        function<&Streamer::update>("", stream_args::moves_float(stream));
    }

    void update(hal::Period) noexcept {
        // Like LinuxCNC 2.9, curr-depth and empty describe the stream as this call found it,
        // before taking a record: the call that takes the last record still shows 1 / FALSE.
        const std::uint32_t used = stream.used();
        curr_depth = static_cast<std::int32_t>(used);
        empty = used == 0;
        if (enable && clocked()) {
            if (stream.pop(record_.data())) {
                for (std::size_t i = 0; i < pins_.size(); ++i) pins_[i]->set(record_[i]);
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

    std::vector<std::unique_ptr<hal::AnyPin>> pins_;
    std::vector<hal::Value> record_;  // sized once here; the realtime path never allocates
    unsigned clock_history_ = 0;
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(streamer, Streamer, "stream file data into HAL in real time",
                           (hal::ComponentOptions{.count_from = "cfg"}), "cfg", "depth")
