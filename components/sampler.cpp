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
#include <variant>
#include <vector>

#include "hal/component.hpp"

namespace {

std::string sampler_layout(const hal::Instance& self) {
    auto cfg = self.arg("cfg");
    if (!cfg || cfg->empty())
        throw hal::Error(
            "cfg=LETTERS[,LETTERS...] is required: one letter per pin "
            "(b bit, f float, s s32, u u32, l s64, k u64)");
    return *cfg;
}

std::uint32_t sampler_depth(const hal::Instance& self) {
    const long depth = self.arg_int("depth", 0);
    if (depth < 1 || depth > (1L << 24))
        throw hal::Error("depth=N (records, 1 to 16777216) is required for " +
                         std::string(self.name()));
    return static_cast<std::uint32_t>(depth);
}

using SampledPin =
    std::variant<std::unique_ptr<hal::In<bool>>, std::unique_ptr<hal::In<double>>,
                 std::unique_ptr<hal::In<std::int32_t>>, std::unique_ptr<hal::In<std::uint32_t>>,
                 std::unique_ptr<hal::In<std::int64_t>>, std::unique_ptr<hal::In<std::uint64_t>>>;

template <class T>
SampledPin make_pin(hal::Instance* owner, const std::string& name) {
    return std::make_unique<hal::In<T>>(owner, name);
}

SampledPin make_sampled_pin(hal::Instance* owner, hal::Type type, std::size_t column) {
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

struct Sampler : hal::Instance {
    hal::Stream stream{this, name(), sampler_layout(*this), sampler_depth(*this)};
    hal::Out<bool> full{this, "full"};
    hal::In<bool> enable{this, "enable", true};
    hal::Out<std::int32_t> curr_depth{this, "curr-depth"};
    hal::IO<std::int32_t> overruns{this, "overruns"};
    hal::IO<std::int32_t> sample_num{this, "sample-num"};

    Sampler() : record_(stream.fields()) {
        for (std::size_t i = 0; i < stream.fields(); ++i)
            pins_.push_back(make_sampled_pin(this, stream.field_type(i), i));
        // Like LinuxCNC, the function needs a floating-point thread only if a float is moved.
        bool moves_float = false;
        for (std::size_t i = 0; i < stream.fields(); ++i)
            moves_float = moves_float || stream.field_type(i) == hal::Type::Float;
        function<&Sampler::update>("", moves_float);
    }

    void update(hal::Period) noexcept {
        if (enable) {
            for (std::size_t i = 0; i < pins_.size(); ++i)
                std::visit([&](auto& pin) { record_[i] = hal::detail::to_value(pin->get()); },
                           pins_[i]);
            if (!stream.push(record_.data())) overruns = overruns + 1;
            sample_num = sample_num + 1;
        }
        const std::uint32_t used = stream.used();
        curr_depth = static_cast<std::int32_t>(used);
        full = used >= stream.depth();
    }

  private:
    std::vector<SampledPin> pins_;
    std::vector<hal::Value> record_;  // sized once here; the realtime path never allocates
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(sampler, Sampler, "sample data from HAL in real time",
                           (hal::ComponentOptions{.count_from = "cfg"}), "cfg", "depth")
