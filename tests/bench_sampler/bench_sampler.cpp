// Realtime cost of one servo period of the motion sampler (Sampler::advance), per program, jerk
// limit and feed override, with the ring kept full (the sampler looks up to 512 records ahead
// above 100 %). Each advance() is timed on its own: Google Benchmark's time is the wall-clock
// mean (manual time), which on a shared machine includes the periods in which the thread was
// preempted; the counters give this thread's CPU time per period (CLOCK_THREAD_CPUTIME_ID, the
// clock's own cost measured and taken off), which does not: mean, 99.9th percentile and the
// largest single period, in ns.
//
//   bench_sampler [--benchmark_* options]    the cost table (docs/benchmarks.md)
//   bench_sampler --digest PROGRAM...        runs each program to its end at 100 %, 120 %, an
//                                            override toggling between them and one toggling
//                                            between 100 % and 30 %, jerk unlimited and
//                                            1e5 mm/s^3; prints a hash of every sample, so two
//                                            builds can be shown to sample identically; exits 1
//                                            if a run leaves the axis limits or does not finish.
//   bench_sampler --holds                    how soon jerk-limited holds and override steps take
//                                            effect (holds.cpp), on a simulated clock.
//   bench_sampler --worst PROGRAM...         the dearest single period (jerk 1e5, toggling
//                                            100 <-> 30 %), each period's least CPU time over
//                                            seven identical runs, so the load counts less.
//   bench_sampler --raises [--short] [--max-start-ms MS]
//                                            how soon jerk-limited override increases take
//                                            effect (raises.cpp); --short: the ctest grid;
//                                            exits 1 if one starts rising later than MS.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <exception>
#include <string>
#include <vector>

#include "holds.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "ngc_program.hpp"
#include "raises.hpp"

namespace {

using namespace motion;

constexpr double kVel_mm_s = 100, kAcc_mm_s2 = 1000, kPeriod_s = 1e-3, kTolerance_mm = 0.01;
constexpr double kJerkLimited_mm_s3 = 1e5;

PlannerConfig config_for(double jerk_mm_s3) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(kVel_mm_s);
    cfg.limits.acc_mm_s2.fill(kAcc_mm_s2);
    cfg.limits.jerk_mm_s3.fill(jerk_mm_s3);
    cfg.servo_period_s = kPeriod_s;
    return cfg;
}

// The override for period i: fixed, or stepping between 100 % and 120 % (Toggle) or between
// 100 % and 30 % (Toggle30: slowing down and speeding up below 1, where a jerk-limited rate
// change checks its room each period) every `toggle` periods (long enough for the rate to get
// there without a jerk limit: 0.2 / 0.1 per s = 2 s).
enum class OverrideMode { At100, At120, Toggle, Toggle30 };
constexpr long kTogglePeriods = 3000;

double override_at(OverrideMode m, long period) {
    switch (m) {
        case OverrideMode::At100:
            return 1.0;
        case OverrideMode::At120:
            return 1.2;
        case OverrideMode::Toggle:
            return (period / kTogglePeriods) % 2 == 0 ? 1.0 : 1.2;
        case OverrideMode::Toggle30:
            return (period / kTogglePeriods) % 2 == 0 ? 1.0 : 0.3;
    }
    return 1.0;
}

const char* mode_name(OverrideMode m) {
    switch (m) {
        case OverrideMode::At100:
            return "100";
        case OverrideMode::At120:
            return "120";
        case OverrideMode::Toggle:
            return "toggle";
        case OverrideMode::Toggle30:
            return "toggle30";
    }
    return "?";
}

double thread_cpu_ns() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e9 + ts.tv_nsec;
}

// The least time two back-to-back readings of the thread CPU clock report (its own cost).
double cpu_clock_overhead_ns() {
    double best = 1e9;
    for (int i = 0; i < 2000; ++i) {
        const double a = thread_cpu_ns();
        best = std::min(best, thread_cpu_ns() - a);
    }
    return best;
}

// ---- cost ------------------------------------------------------------------------------------

struct CostCase {
    std::string program;  // file name in bench/
    double jerk_mm_s3;
    OverrideMode mode;
};

// Endless supply: the program's records over and over (program_end cleared, so the sampler
// never stops; the jump from the last record's end to the first's start does not matter for
// the cost).
class Feeder {
  public:
    explicit Feeder(std::vector<PreparedSegment> recs) : recs_(std::move(recs)) {
        for (auto& r : recs_) r.program_end = false;
    }
    void top_up(SpscRing<PreparedSegment>& ring) {
        while (ring.try_push(recs_[next_])) next_ = (next_ + 1) % recs_.size();
    }

  private:
    std::vector<PreparedSegment> recs_;
    std::size_t next_ = 0;
};

void bm_period(benchmark::State& state, const CostCase& c) {
    const PlannerConfig cfg = config_for(c.jerk_mm_s3);
    const bench::BenchProgram prog =
        bench::read_program(std::string(MOTION_BENCH_DIR) + "/" + c.program, kTolerance_mm);
    Feeder feeder(bench::plan_all(cfg, prog));
    SpscRing<PreparedSegment> ring(1024);
    feeder.top_up(ring);
    Sampler sampler(sampler_config(cfg), ring, prog.start_mm);
    const double overhead_ns = cpu_clock_overhead_ns();
    std::vector<double> all_ns, rising_ns, changing_ns;
    all_ns.reserve(static_cast<std::size_t>(state.max_iterations));
    long period = 0;
    for (auto _ : state) {
        feeder.top_up(ring);
        sampler.set_feed_override(override_at(c.mode, period));
        const double rate_before = sampler.status().rate;
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = thread_cpu_ns();
        MotionSample ms = sampler.advance(kPeriod_s);
        const double c1 = thread_cpu_ns();
        const auto t1 = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(ms);
        state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
        const double ns = std::max(0.0, c1 - c0 - overhead_ns);
        all_ns.push_back(ns);
        if (sampler.status().rate > rate_before) rising_ns.push_back(ns);
        if (sampler.status().rate != rate_before) changing_ns.push_back(ns);
        ++period;
    }
    auto report = [&](std::vector<double>& v, const std::string& prefix) {
        if (v.empty()) return;
        double sum = 0;
        for (double x : v) sum += x;
        std::sort(v.begin(), v.end());
        const std::size_t i999 = std::min(v.size() - 1, v.size() * 999 / 1000);
        state.counters[prefix + "cpu_mean_ns"] = sum / static_cast<double>(v.size());
        state.counters[prefix + "cpu_p999_ns"] = v[i999];
        state.counters[prefix + "cpu_max_ns"] = v.back();
    };
    report(all_ns, "");
    if (c.mode == OverrideMode::Toggle) {
        state.counters["rising_periods"] = static_cast<double>(rising_ns.size());
        report(rising_ns, "rise_");
    }
    if (c.mode == OverrideMode::Toggle30) {  // the periods in which the rate moved
        state.counters["changing_periods"] = static_cast<double>(changing_ns.size());
        report(changing_ns, "change_");
        state.counters["rising_periods"] = static_cast<double>(rising_ns.size());
        report(rising_ns, "rise_");
    }
}

void register_cost_cases() {
    for (const char* program : {"surface_3d.ngc", "tangent_arcs.ngc"})
        for (double jerk : {0.0, kJerkLimited_mm_s3})
            for (OverrideMode mode : {OverrideMode::At100, OverrideMode::At120,
                                      OverrideMode::Toggle, OverrideMode::Toggle30}) {
                const std::string name =
                    fmt::format("period/{}/jerk:{:g}/override:{}", program, jerk, mode_name(mode));
                benchmark::RegisterBenchmark(name.c_str(), bm_period, CostCase{program, jerk, mode})
                    ->UseManualTime()
                    ->Iterations(4 * kTogglePeriods)
                    ->Unit(benchmark::kMicrosecond);
            }
}

// ---- digest ----------------------------------------------------------------------------------

struct Fnv1a {
    std::uint64_t h = 1469598103934665603ull;
    void add(const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    }
    void add(const AxisArray& a) { add(a.data(), sizeof(double) * a.size()); }
};

// Plays the program to its end; false if it left the limits or did not finish.
bool digest_run(const std::string& path, const bench::BenchProgram& prog, double jerk,
                OverrideMode mode) {
    const PlannerConfig cfg = config_for(jerk);
    std::vector<PreparedSegment> recs = bench::plan_all(cfg, prog);
    SpscRing<PreparedSegment> ring(recs.size() + 1);
    for (const auto& r : recs) ring.try_push(r);
    Sampler sampler(sampler_config(cfg), ring, prog.start_mm);
    Fnv1a hash;
    double max_v = 0, max_a = 0, max_j = 0;  // max_j: analytic and from the sampled acceleration
    AxisArray prev_acc{};
    long period = 0;
    constexpr long kMaxPeriods = 10'000'000;
    do {
        sampler.set_feed_override(override_at(mode, period));
        const MotionSample ms = sampler.advance(kPeriod_s);
        hash.add(ms.pos_mm);
        hash.add(ms.vel_mm_s);
        hash.add(ms.acc_mm_s2);
        hash.add(ms.jerk_mm_s3);
        const double rate = sampler.status().rate;
        hash.add(&rate, sizeof rate);
        for (int k = 0; k < kAxes; ++k) {
            max_v = std::max(max_v, std::fabs(ms.vel_mm_s[k]));
            max_a = std::max(max_a, std::fabs(ms.acc_mm_s2[k]));
            const double j_fd = period > 0 ? (ms.acc_mm_s2[k] - prev_acc[k]) / kPeriod_s : 0;
            max_j = std::max({max_j, std::fabs(ms.jerk_mm_s3[k]), std::fabs(j_fd)});
        }
        prev_acc = ms.acc_mm_s2;
        ++period;
    } while (!sampler.status().done && period < kMaxPeriods);
    const bool ok = sampler.status().done && max_v <= kVel_mm_s * (1 + 1e-9) &&
                    max_a <= kAcc_mm_s2 * (1 + 1e-6) &&
                    (jerk == 0 || max_j <= jerk * (1 + 1e-6) + 1e-3);
    fmt::print(
        "{} jerk {:g} override {}: {} periods, max |v| {:.4f}, max |a| {:.3f}{}, "
        "digest {:016x}{}\n",
        path, jerk, mode_name(mode), period, max_v, max_a,
        jerk > 0 ? fmt::format(", max |j| {:.0f}", max_j) : std::string(), hash.h,
        ok ? "" : "  <-- FAILED (limits or end)");
    return ok;
}

int digest_main(int argc, char** argv) {
    bool ok = true;
    for (int i = 2; i < argc; ++i) {
        const bench::BenchProgram prog = bench::read_program(argv[i], kTolerance_mm);
        for (double jerk : {0.0, kJerkLimited_mm_s3})
            for (OverrideMode mode : {OverrideMode::At100, OverrideMode::At120,
                                      OverrideMode::Toggle, OverrideMode::Toggle30})
                ok = digest_run(argv[i], prog, jerk, mode) && ok;
    }
    return ok ? 0 : 1;
}

// --worst: the dearest single period with the machine's noise taken out. The same 12 000
// periods (fixed program, jerk 1e5 mm/s^3, override toggling 100 <-> 30 %) are played kRuns
// times; each period's figure is its least CPU time over the runs (a preemption or a cold
// cache in one run does not count), and the table gives the largest of those, with the means
// over the periods in which the rate rose and fell.
int worst_main(int argc, char** argv) {
    constexpr int kRuns = 7;
    constexpr long kPeriods = 4 * kTogglePeriods;
    for (int i = 2; i < argc; ++i) {
        const PlannerConfig cfg = config_for(kJerkLimited_mm_s3);
        const bench::BenchProgram prog = bench::read_program(argv[i], kTolerance_mm);
        const std::vector<PreparedSegment> recs = bench::plan_all(cfg, prog);
        const double overhead_ns = cpu_clock_overhead_ns();
        std::vector<double> least(kPeriods, 1e300);
        std::vector<int> change(kPeriods, 0);  // +1 rose, -1 fell
        for (int run = 0; run < kRuns; ++run) {
            Feeder feeder(recs);
            SpscRing<PreparedSegment> ring(1024);
            feeder.top_up(ring);
            Sampler sampler(sampler_config(cfg), ring, prog.start_mm);
            for (long p = 0; p < kPeriods; ++p) {
                feeder.top_up(ring);
                sampler.set_feed_override(override_at(OverrideMode::Toggle30, p));
                const double before = sampler.status().rate;
                const double c0 = thread_cpu_ns();
                const MotionSample ms = sampler.advance(kPeriod_s);
                const double c1 = thread_cpu_ns();
                benchmark::DoNotOptimize(ms);
                const std::size_t k = static_cast<std::size_t>(p);
                least[k] = std::min(least[k], std::max(0.0, c1 - c0 - overhead_ns));
                const double after = sampler.status().rate;
                change[k] = after > before ? 1 : after < before ? -1 : 0;
            }
        }
        double worst = 0, rise_sum = 0, fall_sum = 0, rise_worst = 0, fall_worst = 0;
        long worst_at = 0, rises = 0, falls = 0;
        for (std::size_t k = 0; k < least.size(); ++k) {
            if (least[k] > worst) {
                worst = least[k];
                worst_at = static_cast<long>(k);
            }
            if (change[k] > 0) {
                rise_sum += least[k];
                rise_worst = std::max(rise_worst, least[k]);
                ++rises;
            } else if (change[k] < 0) {
                fall_sum += least[k];
                fall_worst = std::max(fall_worst, least[k]);
                ++falls;
            }
        }
        fmt::print(
            "{}: least of {} runs per period, us: dearest period {:.1f} (period {}, {}); rising "
            "{} periods, mean {:.2f}, dearest {:.1f}; falling {} periods, mean {:.2f}, dearest "
            "{:.1f}\n",
            argv[i], kRuns, worst / 1e3, worst_at,
            change[static_cast<std::size_t>(worst_at)] > 0   ? "rising"
            : change[static_cast<std::size_t>(worst_at)] < 0 ? "falling"
                                                             : "steady",
            rises, rises ? rise_sum / rises / 1e3 : 0.0, rise_worst / 1e3, falls,
            falls ? fall_sum / falls / 1e3 : 0.0, fall_worst / 1e3);
    }
    return 0;
}

int raises_main(int argc, char** argv) {
    sampler_raises::Options opt;
    for (int i = 2; i < argc; ++i) {
        if (std::strcmp(argv[i], "--short") == 0) {
            opt.short_grid = true;
        } else if (std::strcmp(argv[i], "--max-start-ms") == 0 && i + 1 < argc) {
            opt.max_start_ms = std::stod(argv[++i]);
        } else {
            fmt::print(stderr, "bench_sampler --raises: unknown argument '{}'\n", argv[i]);
            return 2;
        }
    }
    return sampler_raises::raises_main(opt);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        if (argc >= 2 && std::strcmp(argv[1], "--digest") == 0) return digest_main(argc, argv);
        if (argc == 2 && std::strcmp(argv[1], "--holds") == 0) return sampler_holds::holds_main();
        if (argc >= 2 && std::strcmp(argv[1], "--raises") == 0) return raises_main(argc, argv);
        if (argc >= 3 && std::strcmp(argv[1], "--worst") == 0) return worst_main(argc, argv);
        benchmark::Initialize(&argc, argv);
        if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
        register_cost_cases();
        benchmark::RunSpecifiedBenchmarks();
        benchmark::Shutdown();
        return 0;
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_sampler: {}\n", e.what());
        return 1;
    }
}
