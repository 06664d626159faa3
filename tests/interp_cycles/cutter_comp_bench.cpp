// Cost of cutter radius compensation per move on dense CAM-like input: N short chords (N = 200 000
// by default) of 0.05 mm going round a circle of radius 50 mm (about 32 laps), compensated with a
// tool of radius 3 mm on the outside (G42 on a CCW circle: every joint is an outside corner) and
// on the inside (G41: every joint is an inside corner, trimmed to the intersection). The program
// text has 6 decimals, so its geometry is the core's to within 1e-6 mm.
//   core:      the Compensator alone (push + drain per move)
//   pipeline:  text -> Interpreter -> Executor -> CrcStage -> a counting sink, the same program
//              with G41/G42 minus the same program without compensation, per move
// CPU time (CLOCK_PROCESS_CPUTIME_ID), best of 3 runs. Not a test; run by hand:
//   build-crc/bin/cutter_comp_bench [moves]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "interp/cutter_comp.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/source.hpp"

namespace {

double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

constexpr double kCircleMm = 50.0;
constexpr double kToolRadiusMm = 3.0;
constexpr double kChordMm = 0.05;
const long kChordsPerLap = std::lround(2.0 * std::numbers::pi * kCircleMm / kChordMm);

interp::cutter::Vec2 chord_end(long i) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(i % kChordsPerLap) /
                     static_cast<double>(kChordsPerLap);
    return {kCircleMm * std::cos(a), kCircleMm * std::sin(a)};
}

double core_seconds(long n, interp::cutter::Side side) {
    using namespace interp::cutter;
    Compensator comp(Config{}, Vec2(kCircleMm + 10, 0));
    std::size_t outputs = 0;
    const double t0 = cpu_seconds();
    Move m;
    m.side = side;
    m.radius_mm = kToolRadiusMm;
    for (long i = 0; i <= n; ++i) {
        m.end = chord_end(i);
        m.tag = i + 1;
        comp.push(m);
        outputs += comp.drain().size();
    }
    m.side = Side::Off;
    m.end = {kCircleMm + 10, 0};
    m.tag = n + 2;
    comp.push(m);
    comp.finish();
    outputs += comp.drain().size();
    const double s = cpu_seconds() - t0;
    if (outputs < static_cast<std::size_t>(n)) std::fprintf(stderr, "too few outputs\n");
    return s;
}

struct CountingSink : interp::CanonSink {
    long commands = 0;
    void emit(const interp::Canon&) override { ++commands; }
};

std::string program(long n, const char* comp_code) {
    std::ostringstream f;
    f << std::fixed << std::setprecision(6);
    f << "G90 G17 G0 X" << kCircleMm + 10 << " Y0 F1000\n";
    f << comp_code << " G1 X" << kCircleMm << " Y0 D1\n";
    for (long i = 1; i <= n; ++i) {
        const interp::cutter::Vec2 p = chord_end(i);
        f << "X" << p.x() << " Y" << p.y() << "\n";
    }
    f << "G40 X" << kCircleMm + 10 << " Y0\nM30\n";
    return f.str();
}

double pipeline_seconds(const std::string& text) {
    interp::Settings settings;
    settings.tools.at(1).diameter_mm = 2 * kToolRadiusMm;
    CountingSink sink;
    interp::Executor exec(sink, interp::BackendConfig{}, settings);
    interp::Interpreter in(exec, exec, interp::InterpreterOptions{});
    in.open(interp::Source::from_string("bench.nc", text));
    const double t0 = cpu_seconds();
    in.run();
    return cpu_seconds() - t0;
}

// A compensation error (the input is valid, so that would be a bug) is printed, not fatal.
template <typename F>
double best_of_3(F&& f) {
    double best = 1e300;
    try {
        for (int i = 0; i < 3; ++i) best = std::min(best, f());
    } catch (const std::exception& e) {
        std::printf("error: %s\n", e.what());
        return std::nan("");
    }
    return best;
}

}  // namespace

int main(int argc, char** argv) {
    const long n = argc > 1 ? std::atol(argv[1]) : 200000;
    const double us = 1e6 / static_cast<double>(n);
    using interp::cutter::Side;
    std::printf(
        "%ld chords of %g mm round a circle of radius %g mm, tool radius %g mm, CPU time, "
        "best of 3\n",
        n, kChordMm, kCircleMm, kToolRadiusMm);
    for (const Side side : {Side::Right, Side::Left}) {
        const char* name = side == Side::Right ? "outside (G42)" : "inside (G41)";
        const double core = best_of_3([&] { return core_seconds(n, side); });
        const std::string with = program(n, side == Side::Right ? "G42" : "G41");
        const std::string without = program(n, "G40");
        const double on = best_of_3([&] { return pipeline_seconds(with); });
        const double off = best_of_3([&] { return pipeline_seconds(without); });
        std::printf(
            "%-14s core %.3f us/move   pipeline %.3f us/move with, %.3f without: +%.3f us/move\n",
            name, core * us, on * us, off * us, (on - off) * us);
    }
    return 0;
}
