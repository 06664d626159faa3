// HAL bus benchmark: cost per function call on a chain of and2 instances (simulated clock
// and real-time thread), wake-up error percentiles of a 1 kHz thread, and the same chain on
// LinuxCNC when it is installed. See docs/benchmarks.md for how to run it and read it.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "chain.hpp"
#include "linuxcnc.hpp"
#include "runtime.hpp"
#include "segment.hpp"
#include "stats.hpp"
#include "thread.hpp"

namespace {

// The thread's statistics block is found through its first param ("<thread>.tmax").
static_assert(offsetof(hal::ThreadStats, tmax) == 0);

struct Settings {
    bench::ChainSpec chain;
    int sim_cycles_per_sample = 100;
    int sim_samples = 201;
    double rt_seconds = 10;
    double baseline_seconds = 1;
    bench::LinuxcncOptions lcnc;
};

using Clock = std::chrono::steady_clock;

std::string run(hal::Runtime& rt, const std::string& line) {
    std::string out;
    try {
        rt.execute(bench::split_words(line), out);
    } catch (const hal::Error& e) {
        throw hal::Error(fmt::format("'{}': {}", line, e.what()));
    }
    return out;
}

std::int64_t getp_int(hal::Runtime& rt, const std::string& name) {
    return std::stoll(run(rt, "getp " + name));
}

void expect_output(hal::Runtime& rt, const std::string& pin, const char* want) {
    auto got = run(rt, "getp " + pin);
    if (got.rfind(want, 0) != 0)
        throw hal::Error(
            fmt::format("chain check failed: {} is {} but must be {}", pin, got, want));
}

hal::Runtime::Options options(const char* kind, bool sim) {
    hal::Runtime::Options o;
    o.instance = fmt::format("halbench-{}-{}", ::getpid(), kind);
    o.sim_clock = sim;
    // 1000 and2 need well under 1 MiB; a small segment keeps mlockall (done by `start`) from
    // committing the 256 MiB default reservation of every runtime created after it.
    o.segment_bytes = std::size_t{32} << 20;
    return o;
}

void build_chain(hal::Runtime& rt, const bench::ChainSpec& spec) {
    for (const auto& line : bench::chain_commands(spec)) run(rt, line);
}

// (a) in-process loop: `advance` runs every function at simulated deadlines, no clock reads.
struct SimResult {
    std::vector<double> per_call_ns;
};

SimResult measure_sim(const Settings& s) {
    hal::Runtime rt(options("sim", true));
    build_chain(rt, s.chain);
    run(rt, "start");
    const std::string tail = fmt::format("and2.{}.out", s.chain.length - 1);
    const std::string one_cycle = fmt::format("advance {:.9f}", s.chain.period_ns * 1e-9);
    // The chain must really be a chain: the head's value reaches the tail within one cycle.
    run(rt, one_cycle);
    expect_output(rt, tail, "TRUE");
    run(rt, "setp and2.0.in0 0");
    run(rt, one_cycle);
    expect_output(rt, tail, "FALSE");
    run(rt, "setp and2.0.in0 1");

    const std::string step =
        fmt::format("advance {:.9f}", s.chain.period_ns * 1e-9 * s.sim_cycles_per_sample);
    run(rt, step);  // warm caches
    SimResult r;
    const double calls = static_cast<double>(s.sim_cycles_per_sample) * s.chain.length;
    for (int i = 0; i < s.sim_samples; ++i) {
        const auto t0 = Clock::now();
        run(rt, step);
        const auto t1 = Clock::now();
        r.per_call_ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / calls);
    }
    expect_output(rt, tail, "TRUE");
    return r;
}

// Real-time thread: the thread measures its own cycle (`<thread>.time` pin, ns); we read it with
// getp once per new cycle. Also returns the thread's wake-up histogram for (b).
struct RtResult {
    std::vector<double> cycle_ns;
    std::vector<std::uint64_t> histogram;
    std::int64_t wakeup_max_ns = 0;
    std::uint64_t cycles = 0;
    std::uint64_t late_cycles = 0;
    std::int64_t tmax_ns = 0;
    std::vector<double> wakeup_sampled_ns;  // exact `wakeup-err` of the cycles the poller saw
    std::string warning;
};

RtResult sample_thread(hal::Runtime& rt, const std::string& thread, double seconds) {
    RtResult r;
    r.warning = run(rt, "start");
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    std::int64_t last_cycle = -1;
    while (Clock::now() < end) {
        std::this_thread::sleep_for(std::chrono::microseconds(700));
        const std::int64_t cycle = getp_int(rt, thread + ".cycles");
        if (cycle < 2 || cycle == last_cycle) continue;  // the first cycle runs on cold caches
        last_cycle = cycle;
        r.cycle_ns.push_back(static_cast<double>(getp_int(rt, thread + ".time")));
        r.wakeup_sampled_ns.push_back(static_cast<double>(getp_int(rt, thread + ".wakeup-err")));
    }
    run(rt, "stop");
    const auto& stats = *rt.segment().at<hal::ThreadStats>(rt.lookup(thread + ".tmax").offset);
    r.histogram.assign(std::begin(stats.histogram), std::end(stats.histogram));
    r.wakeup_max_ns = stats.wakeup_max_ns;
    r.cycles = stats.cycles;
    r.late_cycles = stats.late_cycles;
    r.tmax_ns = stats.tmax.s32;
    return r;
}

RtResult measure_baseline(const Settings& s) {
    hal::Runtime rt(options("base", false));
    run(rt, fmt::format("loadrt threads name1={} period1={}", s.chain.thread, s.chain.period_ns));
    return sample_thread(rt, s.chain.thread, s.baseline_seconds);
}

RtResult measure_rt(const Settings& s) {
    hal::Runtime rt(options("rt", false));
    build_chain(rt, s.chain);
    auto r = sample_thread(rt, s.chain.thread, s.rt_seconds);
    expect_output(rt, fmt::format("and2.{}.out", s.chain.length - 1), "TRUE");
    return r;
}

std::string us(double ns) {
    return fmt::format("{:.2f} us", ns / 1000);
}

void print_report(const Settings& s, const SimResult& sim, const RtResult& base, const RtResult& rt,
                  const bench::LinuxcncResult* lcnc) {
    const double n = s.chain.length;
    const double sim_call = bench::median(sim.per_call_ns);
    const double rt_cycle = bench::median(rt.cycle_ns);
    const double base_cycle = bench::median(base.cycle_ns);
    fmt::print("\nHAL bench: chain of {} and2 in one thread, period {} ns ({} cpus)\n\n",
               s.chain.length, s.chain.period_ns, std::thread::hardware_concurrency());
    fmt::print("{:<46} {:>10} {:>12} {:>10}  {}\n", "cost per function call", "ns/call", "cycle",
               "p99 cycle", "samples");
    fmt::print("{:-<46} {:->10} {:->12} {:->10}  {:-<24}\n", "", "", "", "", "");
    fmt::print("{:<46} {:>10.3f} {:>12} {:>10}  {} x {} cycles\n",
               "ours, simulated clock (advance, in-process)", sim_call, us(sim_call * n),
               us(bench::quantile(sim.per_call_ns, 0.99) * n), sim.per_call_ns.size(),
               s.sim_cycles_per_sample);
    fmt::print("{:<46} {:>10.3f} {:>12} {:>10}  {} cycles\n",
               "ours, real-time thread (<thread>.time)", rt_cycle / n, us(rt_cycle),
               us(bench::quantile(rt.cycle_ns, 0.99)), rt.cycle_ns.size());
    fmt::print("{:<46} {:>10.3f} {:>12} {:>10}  empty thread: {} ({} cycles)\n",
               "ours, real-time, minus empty-thread cycle", (rt_cycle - base_cycle) / n,
               us(rt_cycle - base_cycle), "", us(base_cycle), base.cycle_ns.size());
    if (lcnc && lcnc->ran) {
        const double l_cycle = bench::median(lcnc->cycle_ns);
        fmt::print("{:<46} {:>10.3f} {:>12} {:>10}  {} cycles (TSC {:.1f} MHz)\n",
                   "LinuxCNC 2.9, servo-thread.time (TSC ticks)", l_cycle / n, us(l_cycle),
                   us(bench::quantile(lcnc->cycle_ns, 0.99)), lcnc->cycle_ns.size(),
                   lcnc->tsc_hz / 1e6);
        fmt::print("{:<46} {:>10.2f}x\n", "ratio LinuxCNC / ours (real-time thread)",
                   l_cycle / rt_cycle);
        fmt::print("max cycle (tmax, includes start-up): ours {}, LinuxCNC {}\n", us(rt.tmax_ns),
                   us(lcnc->tmax_ns));
        if (!lcnc->rtapi_note.empty()) fmt::print("note: {}\n", lcnc->rtapi_note);
    } else {
        fmt::print("max cycle (tmax, includes start-up): ours {}\n", us(rt.tmax_ns));
        if (lcnc) fmt::print("LinuxCNC: not measured: {}\n", lcnc->why_not);
    }
    fmt::print("target: <= 2 ns per call -> {}\n",
               rt_cycle / n <= 2.0 ? "met (real-time thread)" : "NOT met (real-time thread)");

    fmt::print("\nwake-up error of the {:g} kHz thread over {:.1f} s ({} cycles, {} late)\n",
               1e6 / static_cast<double>(s.chain.period_ns), s.rt_seconds, rt.cycles,
               rt.late_cycles);
    fmt::print(
        "histogram: every cycle, recorded by the thread itself; each percentile is the bucket "
        "holding it (12.5 % wide)\n");
    fmt::print(
        "sampled: exact `wakeup-err` of the {} cycles the poller read (a poller delayed by "
        "load misses cycles, so the tail may be light)\n",
        rt.wakeup_sampled_ns.size());
    fmt::print("  {:<6} {:>22}  {:>10}\n", "", "histogram", "sampled");
    for (auto [label, q] : {std::pair{"p50", 0.5}, {"p90", 0.9}, {"p99", 0.99}, {"p99.9", 0.999}}) {
        auto b = bench::histogram_quantile(rt.histogram, q);
        fmt::print("  {:<6} {:>9.1f} .. {:>6.1f} us  {:>7.1f} us\n", label, b.floor_ns / 1000.0,
                   b.ceil_ns / 1000.0, bench::quantile(rt.wakeup_sampled_ns, q) / 1000.0);
    }
    fmt::print("  {:<6} {:>9.1f} us (exact, every cycle)\n", "max", rt.wakeup_max_ns / 1000.0);
    if (!rt.warning.empty()) fmt::print("start said: {}", rt.warning);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "bench_hal: HAL bus function-call cost and thread wake-up error (see docs/benchmarks.md)"};
    Settings s;
    bool smoke = false, no_linuxcnc = false;
    app.add_option("--chain", s.chain.length, "and2 instances in the chain")
        ->check(CLI::Range(2, 100000));
    app.add_option("--period", s.chain.period_ns,
                   "thread period, ns (wake-up figures are for this period)")
        ->check(CLI::Range(std::int64_t{10'000}, std::int64_t{1'000'000'000}));
    app.add_option("--sim-samples", s.sim_samples, "simulated-clock samples")
        ->check(CLI::Range(1, 100000));
    app.add_option("--sim-cycles", s.sim_cycles_per_sample, "cycles per simulated-clock sample")
        ->check(CLI::Range(1, 100000));
    app.add_option("--seconds", s.rt_seconds, "real-time run of the 1 kHz thread (wake-up error)")
        ->check(CLI::Range(0.1, 3600.0));
    app.add_option("--linuxcnc-cycles", s.lcnc.cycles, "LinuxCNC cycles to sample")
        ->check(CLI::Range(100, 1000000));
    app.add_option("--linuxcnc-halrun", s.lcnc.halrun, "LinuxCNC's halrun");
    app.add_flag("--no-linuxcnc", no_linuxcnc, "skip the LinuxCNC comparison");
    app.add_flag("--smoke", smoke, "a few seconds, no LinuxCNC: checks the bench runs (ctest)");
    CLI11_PARSE(app, argc, argv);
    if (smoke) {
        s.sim_samples = 11;
        s.rt_seconds = 0.5;
        s.baseline_seconds = 0.2;
        no_linuxcnc = true;
    }
    try {
        const auto sim = measure_sim(s);
        const auto base = measure_baseline(s);
        const auto rt = measure_rt(s);
        bench::LinuxcncResult lcnc;
        if (!no_linuxcnc) lcnc = bench::run_linuxcnc_chain(s.chain, s.lcnc);
        print_report(s, sim, base, rt, no_linuxcnc ? nullptr : &lcnc);
        if (rt.cycle_ns.empty() || base.cycle_ns.empty()) {
            fmt::print(stderr, "bench_hal: the real-time thread produced no samples\n");
            return 1;
        }
        return 0;
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_hal: {}\n", e.what());
        return 1;
    }
}
