// sampler: copies a set of pins into a stream once per call, for halsampler to write to a
// file; LinuxCNC-compatible (`loadrt sampler depth=D[,D...] cfg=LETTERS[,LETTERS...]`, one
// instance sampler.N with function sampler.N per cfg item).
//
// cfg has one letter per pin: b bit, f float, s s32, u u32 (as LinuxCNC), plus l s64 and
// k u64; upper case is accepted too. Pin sampler.N.pin.M samples column M. The stream is
// named after the instance ("sampler.0"), holds `depth` records with the fields in cfg order,
// and is read by a userspace client (halsampler) through the client library.
//
// While enable is TRUE each call takes one sample and increments sample-num; when the stream
// is full the sample is lost and overruns counts it. curr-depth is the number of records
// waiting, full is TRUE while no record fits. overruns and sample-num are I/O pins so that
// setp can reset them, as in LinuxCNC.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/component.hpp"
#include "stream_args.hpp"

namespace {

struct Sampler : hal::Instance {
    hal::Stream stream{this, name(), stream_args::layout(*this), stream_args::depth(*this)};
    hal::Out<bool> full{this, "full"};
    hal::In<bool> enable{this, "enable", true};
    hal::Out<std::int32_t> curr_depth{this, "curr-depth"};
    hal::IO<std::int32_t> overruns{this, "overruns"};
    hal::IO<std::int32_t> sample_num{this, "sample-num"};

    Sampler() : record_(stream.fields()) {
        for (std::size_t i = 0; i < stream.fields(); ++i)
            pins_.push_back(std::make_unique<hal::AnyPin>(this, "pin." + std::to_string(i),
                                                          stream.field_type(i), hal::Dir::In));
        function<&Sampler::update>("", stream_args::moves_float(stream));
    }

    void update(hal::Period) noexcept {
        if (enable) {
            for (std::size_t i = 0; i < pins_.size(); ++i) record_[i] = pins_[i]->get();
            if (!stream.push(record_.data())) overruns = overruns + 1;
            sample_num = sample_num + 1;
        }
        const std::uint32_t used = stream.used();
        curr_depth = static_cast<std::int32_t>(used);
        full = used >= stream.depth();
    }

  private:
    std::vector<std::unique_ptr<hal::AnyPin>> pins_;
    std::vector<hal::Value> record_;  // sized once here; the realtime path never allocates
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(sampler, Sampler, "sample data from HAL in real time",
                           (hal::ComponentOptions{.count_from = "cfg"}), "cfg", "depth")
