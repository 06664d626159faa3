// Components that exist only to exercise the runtime: every pin type, args, a shared
// function, a stream, a constructor that fails half way, a function that overruns.
#include <time.h>

#include <fmt/format.h>

#include "hal/component.hpp"

namespace {

struct Probe : hal::Instance {
    hal::In<bool> in_bit{this, "in-bit"};
    hal::In<double> in_float{this, "in-float", 1.5};
    hal::In<std::int32_t> in_s32{this, "in-s32", -3};
    hal::In<std::uint32_t> in_u32{this, "in-u32"};
    hal::In<std::int64_t> in_s64{this, "in-s64"};
    hal::In<std::uint64_t> in_u64{this, "in-u64"};
    hal::Out<double> out_float{this, "out-float"};
    hal::Out<bool> out_bit{this, "out-bit"};
    hal::IO<double> io_float{this, "io-float"};
    hal::Out<std::uint64_t> cycles{this, "cycles"};
    hal::Param<double> gain{this, "gain", 2.0};
    hal::Param<std::int32_t> ro{this, "ro", 7, hal::ParamDir::RO};
    hal::Array<hal::Out<std::int32_t>> taps{this, "tap-{:02}", static_cast<std::size_t>(arg_int("taps", 2))};
    std::uint64_t count = 0;

    Probe() { shared_function<&Probe::tick>("tick-all"); function<&Probe::update>(""); }
    void update(hal::Period) noexcept {
        out_float = in_float * gain;
        out_bit = !in_bit;
        cycles = ++count;
        for (std::size_t i = 0; i < taps.size(); ++i) taps[i] = static_cast<std::int32_t>(i) + in_s32;
    }
    void tick(hal::Period) noexcept { ++count; }
};

struct Failing : hal::Instance {
    hal::In<bool> a{this, "a"};
    hal::Out<bool> fixed{this, fmt::format("=fixed.{}.b", index())};
    hal::Out<bool> b{this, "b"};
    Failing() {
        if (index() == arg_int("fail-at", -1)) throw hal::Error("refusing to build this instance");
    }
    void update(hal::Period) noexcept { b = a; }
};

struct Spinner : hal::Instance {
    hal::Param<std::int64_t> spin_ns{this, "spin-ns", 0};
    hal::Out<std::uint64_t> calls{this, "calls"};
    // TRUE while a spin is under way, so a test can stop the thread inside that very cycle.
    hal::Out<bool> spinning{this, "spinning"};
    hal::Out<std::uint64_t> last_spin_call{this, "last-spin-call"};  // `calls` of the last spin
    std::uint64_t n = 0;
    void update(hal::Period) noexcept {
        // Busy-waits once for spin-ns, then clears it: a single deliberately late cycle.
        std::int64_t spin = spin_ns;
        if (spin > 0) {
            spinning = true;
            timespec t0, t;
            clock_gettime(CLOCK_MONOTONIC, &t0);
            do clock_gettime(CLOCK_MONOTONIC, &t);
            while ((t.tv_sec - t0.tv_sec) * 1'000'000'000LL + (t.tv_nsec - t0.tv_nsec) < spin);
            spin_ns = 0;
            spinning = false;
            last_spin_call = n + 1;
        }
        calls = ++n;
    }
};

struct Streamer : hal::Instance {
    hal::Stream stream{this, std::string(name()), "fb", 8};
    hal::In<double> value{this, "value"};
    hal::Out<std::int32_t> pushed{this, "pushed"};
    std::int32_t n = 0;
    void update(hal::Period) noexcept {
        hal::Value rec[2];
        rec[0].f = value;
        rec[1].b = (n % 2) == 0;
        if (stream.push(rec)) pushed = ++n;
    }
};

// The consumer end of another instance's stream (`from=NAME`), attached in-process.
struct StreamReader : hal::Instance {
    hal::Stream stream = hal::Stream::attach(this, arg("from").value_or(""),
                                            arg("layout").value_or("fb"));
    hal::Out<double> value{this, "value"};
    hal::Out<bool> flag{this, "flag"};
    hal::Out<std::int32_t> popped{this, "popped"};
    std::int32_t n = 0;
    void update(hal::Period) noexcept {
        hal::Value rec[2];
        if (!stream.pop(rec)) return;
        value = rec[0].f;
        flag = rec[1].b;
        popped = ++n;
    }
};

}  // namespace

#if defined(TEST_COMPONENT_PROBE)
HAL_COMPONENT(tprobe, Probe, "runtime test: every pin type", "taps")
#elif defined(TEST_COMPONENT_FAILING)
HAL_COMPONENT(tfailing, Failing, "runtime test: constructor failure", "fail-at")
#elif defined(TEST_COMPONENT_SPINNER)
HAL_COMPONENT(tspinner, Spinner, "runtime test: late cycles")
#elif defined(TEST_COMPONENT_STREAM)
HAL_COMPONENT(tstream, Streamer, "runtime test: stream producer")
#elif defined(TEST_COMPONENT_STREAMREADER)
HAL_COMPONENT(tstreamreader, StreamReader, "runtime test: consumer of another instance's stream",
              "from", "layout")
#elif defined(TEST_COMPONENT_BADABI)
extern "C" __attribute__((visibility("default"))) const hal::ComponentDescriptor* cnc_hal_component() {
    static const char* const args[] = {nullptr};
    static const hal::ComponentDescriptor d{hal::kAbiVersion + 100, "tbadabi", "wrong ABI", args,
                                            &hal::detail::create_instance<Probe>, {}};
    return &d;
}
#elif defined(TEST_COMPONENT_NOSYM)
extern "C" int not_a_component() { return 0; }
#endif
