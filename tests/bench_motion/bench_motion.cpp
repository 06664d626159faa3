// Planner benchmark: motion time against the feed-rate bound, and planning throughput.
// See docs/motion-planner.md ("Benchmark") for how to run it and what the figures mean.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel_bound.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "ngc_program.hpp"
#include "trace_check.hpp"

namespace {

using namespace motion;

struct Settings {
    double vel_mm_s = 100, acc_mm_s2 = 1000, period_s = 1e-3, tolerance_mm = 0.01;
    double reserve = -1;  // < 0: the planner's defaults (PlannerConfig)
    double junction_share = PlannerConfig{}.junction_share;
};

AxisLimits limits_for(const Settings& s) {
    AxisLimits lim;
    lim.vel_mm_s.fill(s.vel_mm_s);
    lim.acc_mm_s2.fill(s.acc_mm_s2);
    return lim;
}

PlannerConfig config_for(const Settings& s, double jerk) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(s.vel_mm_s);
    cfg.limits.acc_mm_s2.fill(s.acc_mm_s2);
    cfg.limits.jerk_mm_s3.fill(jerk);
    cfg.servo_period_s = s.period_s;
    if (s.reserve >= 0) cfg.override_reserve = cfg.override_reserve_no_jerk = s.reserve;
    cfg.junction_share = s.junction_share;
    return cfg;
}

double bound_s(const Settings& s, const bench::BenchProgram& prog) {
    double t = 0;
    AxisArray pos = prog.start_mm;
    for (const PathSegment& seg : prog.segments) {
        double f = seg.rapid ? s.vel_mm_s : std::min(seg.feed_mm_s, s.vel_mm_s);
        t += bench::programmed_length_mm(seg, pos) / f;
        pos = seg.end_mm;
    }
    return t + prog.dwell_s;
}

struct RunResult {
    double planned_s = 0;
    double sampled_s = 0;
    AxisArray max_vel{}, max_acc{};
    double end_error_mm = 0;
};

// Plays the plan through the realtime sampler at the servo period, as the servo thread would.
// trace_out: if open, one "X Y Z" line per period (the format of bench/linuxcnc/trace.hal).
RunResult run(const PlannerConfig& cfg, const bench::BenchProgram& prog,
              std::FILE* trace_out = nullptr) {
    RunResult res;
    std::vector<PreparedSegment> recs = bench::plan_all(cfg, prog);
    for (const auto& r : recs) res.planned_s += r.profile.duration_s;
    SpscRing<PreparedSegment> ring(recs.size() + 1);
    for (const auto& r : recs) ring.try_push(r);
    Sampler sampler(sampler_config(cfg), ring, prog.start_mm);
    MotionSample ms;
    long periods = 0;
    do {
        ms = sampler.advance(cfg.servo_period_s);
        ++periods;
        if (trace_out)
            std::fprintf(trace_out, "%f %f %f\n", ms.pos_mm[0], ms.pos_mm[1], ms.pos_mm[2]);
        for (int k = 0; k < kAxes; ++k) {
            res.max_vel[k] = std::max(res.max_vel[k], std::fabs(ms.vel_mm_s[k]));
            res.max_acc[k] = std::max(res.max_acc[k], std::fabs(ms.acc_mm_s2[k]));
        }
    } while (!sampler.status().done && periods < 100'000'000);
    // Dwells stand still for their time: the same on both sides of the ratio.
    res.sampled_s = periods * cfg.servo_period_s + prog.dwell_s;
    res.planned_s += prog.dwell_s;
    const AxisArray& end = prog.segments.back().end_mm;
    for (int k = 0; k < kAxes; ++k)
        res.end_error_mm = std::max(res.end_error_mm, std::fabs(ms.pos_mm[k] - end[k]));
    return res;
}

// Lines where the plan spends the most time beyond length / min(F, vmax).
void print_excess(const Settings& s, const PlannerConfig& cfg, const bench::BenchProgram& prog,
                  int count) {
    std::vector<PreparedSegment> recs = bench::plan_all(cfg, prog);
    std::map<int, double> spent, ideal;
    for (const auto& r : recs) spent[r.line] += r.profile.duration_s;
    AxisArray pos = prog.start_mm;
    for (const PathSegment& seg : prog.segments) {
        double f = seg.rapid ? s.vel_mm_s : std::min(seg.feed_mm_s, s.vel_mm_s);
        ideal[seg.line] += bench::programmed_length_mm(seg, pos) / f;
        pos = seg.end_mm;
    }
    std::vector<std::pair<double, int>> excess;
    for (const auto& [line, t] : spent) excess.emplace_back(t - ideal[line], line);
    std::sort(excess.rbegin(), excess.rend());
    for (int i = 0; i < count && i < int(excess.size()); ++i)
        fmt::print("  line {:4}: {:+.4f} s over its bound\n", excess[i].second, excess[i].first);
}

double thread_cpu_s() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

// One planning pass over the program, as the throughput counts it. Not inlined so that a
// profiler can count one pass: `valgrind --tool=callgrind --toggle-collect='*plan_pass*'`
// gives instructions per pass (docs/benchmarks.md, planning throughput). The records are taken
// by reference, as the motion component's feeder takes them (ProgramFeeder::collect copies
// each once, into its own outbox: the consumer's work, not planning); returns their summed
// duration, so that each is read.
[[gnu::noinline]] double plan_pass(const PlannerConfig& cfg, const bench::BenchProgram& prog) {
    double duration_s = 0;
    Planner planner(cfg, prog.start_mm);
    for (const PathSegment& seg : prog.segments) {
        planner.push(seg);
        while (const PreparedSegment* rec = planner.pop_ref())
            duration_s += rec->profile.duration_s;
    }
    planner.finish();
    while (const PreparedSegment* rec = planner.pop_ref()) duration_s += rec->profile.duration_s;
    return duration_s;
}

// Segments planned per second of this thread's CPU time (the machine may be shared, so wall
// time would measure the neighbours too). The thread's CPU clock is a system call (about
// 0.5 us on the bench VM, 1 % of a pass of ex22 and 7 % of one of ex07), so it is read after
// batches of passes, doubled until a batch takes 1 % of min_s: then the reads cost under
// 0.1 % of the time measured.
double throughput_seg_s(const PlannerConfig& cfg, const bench::BenchProgram& prog, double min_s) {
    double t0 = thread_cpu_s();
    long segs = 0;
    double elapsed = 0;
    double planned_s = 0;
    long batch = 1;
    do {
        for (long i = 0; i < batch; ++i) {
            planned_s += plan_pass(cfg, prog);
            segs += long(prog.segments.size());
        }
        const double before_s = elapsed;
        elapsed = thread_cpu_s() - t0;
        if (elapsed - before_s < min_s / 100) batch *= 2;
    } while (elapsed < min_s);
    // Kept, so that the records' reads are not optimised away.
    [[maybe_unused]] volatile double sink_s = planned_s;
    return segs / elapsed;
}

// FNV-1a over every planned value of every record, bit for bit (so -0 and +0 differ): a change
// meant to make the planner faster without changing a plan must leave it unchanged.
class PlanDigest {
  public:
    void add(const PreparedSegment& r) {
        const Element& g = r.geom;
        add_bits(static_cast<std::uint64_t>(g.kind));
        add(g.length_mm);
        for (const AxisArray* a : {&g.origin, &g.a, &g.b, &g.c, &g.end})
            for (double x : *a) add(x);
        add(g.radius_mm), add(g.theta0_rad), add(g.sweep_rad);
        const Profile1D& p = r.profile;
        add_bits(p.count);
        for (int i = 0; i < p.count; ++i) {
            const ProfilePhase& ph = p.phases[i];
            add(ph.t0_s), add(ph.s0_mm), add(ph.v0_mm_s), add(ph.a0_mm_s2), add(ph.j_mm_s3);
            add(r.phase_rate_cap[i]);
        }
        add(p.duration_s), add(p.peak_v_mm_s), add(p.peak_a_mm_s2), add(p.peak_j_mm_s3);
        add_bits(static_cast<std::uint32_t>(r.line)), add_bits(r.seq), add_bits(r.move_id);
        add_bits(r.rapid), add_bits(r.program_end);
    }
    std::uint64_t value() const { return h_; }

  private:
    void add(double x) {
        std::uint64_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        add_bits(bits);
    }
    void add_bits(std::uint64_t v) {
        for (int i = 0; i < 8; ++i, v >>= 8) h_ = (h_ ^ (v & 0xff)) * 0x100000001b3ULL;
    }
    std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

int print_plan_digests(const Settings& s, const std::vector<std::string>& programs,
                       const std::vector<double>& jerks) {
    fmt::print("program,jerk_mm_s3,records,digest\n");
    for (const std::string& program : programs) {
        bench::BenchProgram prog = bench::read_program(program, s.tolerance_mm);
        for (double j : jerks) {
            PlanDigest d;
            std::vector<PreparedSegment> recs = bench::plan_all(config_for(s, j), prog);
            for (const PreparedSegment& r : recs) d.add(r);
            fmt::print("{},{:g},{},{:016x}\n", program, j, recs.size(), d.value());
        }
    }
    return 0;
}

struct Row {
    std::string program;
    double jerk = 0;
    std::size_t segments = 0;
    double bound_s = 0;
    RunResult run;
    double accel_bound_s = 0;
    double seg_per_s = 0;
};

void print_row_text(const Row& r, double base_s) {
    std::string label = r.jerk > 0 ? fmt::format("jerk {:g} mm/s^3", r.jerk) : "jerk unlimited";
    double motion_s = r.run.sampled_s;
    fmt::print(
        "{} {}: {} segments, motion time {:.3f} s (planned {:.4f} s), bound {:.3f} s, "
        "ratio {:.4f}, acceleration-aware bound {:.3f} s, ratio {:.4f}",
        r.program, label, r.segments, motion_s, r.run.planned_s, r.bound_s, motion_s / r.bound_s,
        r.accel_bound_s, motion_s / r.accel_bound_s);
    if (r.jerk > 0 && base_s > 0) fmt::print(", extra {:+.3f} s vs unlimited", motion_s - base_s);
    fmt::print(
        "\n  max |v| xyz {:.2f} {:.2f} {:.2f} mm/s, max |a| xyz {:.1f} {:.1f} {:.1f} mm/s^2, "
        "end error {:.2e} mm",
        r.run.max_vel[0], r.run.max_vel[1], r.run.max_vel[2], r.run.max_acc[0], r.run.max_acc[1],
        r.run.max_acc[2], r.run.end_error_mm);
    if (r.seg_per_s > 0) fmt::print(", planning {:.3g} segments per CPU second", r.seg_per_s);
    fmt::print("\n");
}

void print_row_csv(const Row& r) {
    fmt::print("{},{:g},{},{:.4f},{:.4f},{:.4f},{:.0f},{:.4f},{:.4f}\n", r.program, r.jerk,
               r.segments, r.bound_s, r.run.sampled_s, r.run.sampled_s / r.bound_s, r.seg_per_s,
               r.accel_bound_s, r.run.sampled_s / r.accel_bound_s);
}

// The smoke run must at least end where the program ends, within the limits.
bool within_limits(const Settings& s, const RunResult& r) {
    bool ok = r.end_error_mm <= 1e-9;
    for (int k = 0; k < kAxes; ++k)
        ok = ok && r.max_vel[k] <= s.vel_mm_s * (1 + 1e-9) &&
             r.max_acc[k] <= s.acc_mm_s2 * (1 + 1e-9);
    return ok;
}

int print_trace_check(const Settings& s, const std::string& program, const std::string& path,
                      double quantum_mm) {
    bench::BenchProgram prog = bench::read_program(program, s.tolerance_mm);
    bench::TraceReport r =
        bench::check_trace(prog, bench::read_trace(path), s.period_s, quantum_mm);
    double lb = bench::accel_lower_bound(prog, limits_for(s)).time_s;
    fmt::print("{} against {}:\n", path, program);
    fmt::print("  {} samples = {:.3f} s (bound {:.3f} s, acceleration-aware bound {:.3f} s)\n",
               r.samples, r.samples * s.period_s, bound_s(s, prog), lb);
    fmt::print("  max distance from the path {:.4f} mm near line {} (trace line {}, tolerance there "
               "{} mm); {} samples beyond their tolerance + {:g} mm\n",
               r.max_deviation_mm, r.deviation_line, r.deviation_sample + 1, r.deviation_tolerance_mm,
               r.samples_over_tolerance, quantum_mm);
    fmt::print("  on feed moves: max {:.4f} mm, {} samples beyond; on rapids: max {:.4f} mm, {} "
               "samples beyond\n",
               r.max_deviation_feed_mm, r.over_tolerance_feed, r.max_deviation_rapid_mm,
               r.over_tolerance_rapid);
    std::vector<std::pair<double, int>> worst;
    for (const auto& [line, d] : r.over_by_line) worst.emplace_back(d, line);
    std::sort(worst.rbegin(), worst.rend());
    if (!worst.empty()) fmt::print("  lines beyond the tolerance (worst first):");
    for (std::size_t i = 0; i < worst.size() && i < 8; ++i)
        fmt::print(" {} ({:.4f} mm)", worst[i].second, worst[i].first);
    if (worst.size() > 8) fmt::print(" and {} more", worst.size() - 8);
    if (!worst.empty()) fmt::print("\n");
    fmt::print("  max |v| xyz {:.2f} {:.2f} {:.2f} mm/s, max |a| xyz {:.1f} {:.1f} {:.1f} mm/s^2 "
               "(finite differences; +-{:.1f} mm/s^2 from the {:g} mm resolution)\n",
               r.max_vel_mm_s[0], r.max_vel_mm_s[1], r.max_vel_mm_s[2], r.max_acc_mm_s2[0],
               r.max_acc_mm_s2[1], r.max_acc_mm_s2[2], 4 * quantum_mm / (s.period_s * s.period_s),
               quantum_mm);
    fmt::print("  max path speed / feed {:.4f}, end error {:.2e} mm\n", r.max_speed_over_feed,
               r.end_error_mm);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "Motion planner benchmark: motion time against the bound sum(length / min(F, vmax)) and "
        "planning throughput, for each program and each jerk limit"};
    std::vector<std::string> programs;
    std::vector<double> jerks;
    Settings s;
    bool smoke = false, csv = false;
    int excess = 0;
    double min_cpu_s = 0.5;
    app.add_option("programs", programs,
                   "G-code files (default: tests/bench_motion/tp_default.ngc)");
    app.add_option("--jerk", jerks, "jerk limit to run, mm/s^3 (0 = unlimited; repeatable)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
        ->delimiter(',');
    app.add_flag("--csv", csv,
                 "one row per (program, jerk): "
                 "program,jerk_mm_s3,segments,bound_s,motion_s,ratio,plan_seg_per_s,accel_bound_s,"
                 "accel_ratio");
    app.add_option("--vel", s.vel_mm_s, "per-axis velocity limit, mm/s");
    app.add_option("--acc", s.acc_mm_s2, "per-axis acceleration limit, mm/s^2");
    app.add_option("--reserve", s.reserve,
                   "share of acc/jerk kept for override and hold, with and without a jerk limit "
                   "(default: the planner's, override_reserve / override_reserve_no_jerk)");
    app.add_option("--junction-share", s.junction_share,
                   "share of acc/jerk for non-smooth junctions");
    app.add_option("--tolerance", s.tolerance_mm,
                   "blend tolerance (G64 P) for moves the program sets none for, mm");
    app.add_option("--excess", excess, "list the N lines with the most time over their bound");
    app.add_option("--min-cpu", min_cpu_s, "CPU seconds to spend measuring each throughput");
    app.add_flag("--smoke", smoke, "one quick pass (jerk unlimited, no throughput), for ctest");
    bool digest = false;
    app.add_flag("--plan-digest", digest,
                 "print a digest of every planned record (bit for bit) per program and jerk, "
                 "then exit: a change that only makes planning faster must leave it unchanged");
    std::string trace_out, trace_check;
    double trace_quantum_mm = 1e-6;
    app.add_option("--trace-out", trace_out,
                   "write our commanded X Y Z per servo period to this file (first program and "
                   "jerk)");
    app.add_option("--trace-check", trace_check,
                   "check a recorded trace (X Y Z per servo period, bench/linuxcnc/run.sh "
                   "--trace) against the first program's path and the limits, then exit");
    app.add_option("--trace-quantum", trace_quantum_mm,
                   "resolution of the trace's numbers, mm (halsampler prints 6 decimals)");
    CLI11_PARSE(app, argc, argv);
    if (programs.empty()) programs.push_back(MOTION_BENCH_DEFAULT_PROGRAM);
    if (jerks.empty() || smoke) jerks = {0};

    try {
        if (digest) return print_plan_digests(s, programs, jerks);
        if (!trace_check.empty())
            return print_trace_check(s, programs.front(), trace_check, trace_quantum_mm);
        if (csv)
            fmt::print(
                "program,jerk_mm_s3,segments,bound_s,motion_s,ratio,plan_seg_per_s,accel_bound_s,"
                "accel_ratio\n");
        else
            fmt::print(
                "settings: {} mm/s, {} mm/s^2 per axis, servo {} Hz, default G64 P{}, "
                "reserve {} (jerk-limited) / {} (unlimited), junction share {}\n",
                s.vel_mm_s, s.acc_mm_s2, 1 / s.period_s, s.tolerance_mm,
                config_for(s, 1).override_reserve, config_for(s, 0).override_reserve_no_jerk,
                s.junction_share);
        for (const std::string& program : programs) {
            bench::BenchProgram prog = bench::read_program(program, s.tolerance_mm);
            if (prog.segments.empty()) throw std::runtime_error(program + ": no moves");
            double base_s = 0;
            for (double j : jerks) {
                PlannerConfig cfg = config_for(s, j);
                std::FILE* trace = nullptr;
                if (!trace_out.empty() && program == programs.front() && j == jerks.front()) {
                    trace = std::fopen(trace_out.c_str(), "w");
                    if (!trace) throw std::runtime_error(trace_out + ": cannot write the trace");
                }
                Row row{program, j, prog.segments.size(), bound_s(s, prog), run(cfg, prog, trace),
                        0};
                if (trace) std::fclose(trace);
                row.accel_bound_s = bench::accel_lower_bound(prog, limits_for(s)).time_s;
                if (!smoke) row.seg_per_s = throughput_seg_s(cfg, prog, min_cpu_s);
                if (j == 0) base_s = row.run.sampled_s;
                if (csv)
                    print_row_csv(row);
                else
                    print_row_text(row, base_s);
                if (excess > 0 && !csv) print_excess(s, cfg, prog, excess);
                // Our run keeps the limits and the tolerance, so it cannot beat a lower bound.
                if (smoke && row.run.sampled_s < row.accel_bound_s - 1e-9) {
                    std::fprintf(stderr, "bench_motion: motion time %.4f s is below the "
                                 "acceleration-aware lower bound %.4f s\n",
                                 row.run.sampled_s, row.accel_bound_s);
                    return 1;
                }
                if (smoke && !within_limits(s, row.run)) {
                    std::fprintf(stderr,
                                 "bench_motion: smoke run left the limits or the path end\n");
                    return 1;
                }
            }
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_motion: %s\n", e.what());
        return 1;
    }
    return 0;
}
