// Front-end throughput: source -> lexer -> parser -> control flow with an executor that only
// counts blocks, so the figure is the front end's share of a whole run. Prints blocks/s and
// peak RSS for the three program shapes. Not a test; run by hand:
//   build/bin/interp_front_bench [lines]
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>

#include "fakes.hpp"
#include "interp/interpreter.hpp"

namespace {

struct CountingExecutor : interp::BlockExecutor {
    long blocks = 0;
    void execute(const interp::Block&) override { ++blocks; }
    void end_of_input(const interp::SourceLoc&) override {}
};

double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
}

void measure(const char* what, const std::string& path) {
    interp::test::FakeMachine machine;
    CountingExecutor exec;
    interp::Interpreter in(exec, machine);
    // CPU time as well as wall time: on a loaded machine the CPU figure is the stable one.
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    in.open(path);
    in.run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double c = cpu_seconds() - c0;
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    std::printf(
        "%-24s %8ld blocks  wall %6.3f s = %5.2f M/s  cpu %6.3f s = %5.2f M/s  peak RSS %ld KiB\n",
        what, exec.blocks, s, exec.blocks / s / 1e6, c, exec.blocks / c / 1e6, ru.ru_maxrss);
}

}  // namespace

int main(int argc, char** argv) {
    const long lines = argc > 1 ? std::atol(argv[1]) : 500000;
    const std::string dir = "/tmp/interp_front_bench_" + std::to_string(::getpid());
    const std::string surf = dir + "_surf.nc", arcs = dir + "_arcs.nc", loop = dir + "_loop.nc";
    {
        std::ofstream f(surf);
        f << "G90 G21 G17\n";
        for (long i = 0; i < lines; ++i)
            f << "G1 X" << (i % 500) * 0.1 << " Y" << (i / 500) * 0.2 << " Z-1.25 F1200\n";
        f << "M30\n";
    }
    {
        std::ofstream f(arcs);
        f << "G90 G17 G0 X10 Y0\n";
        for (long i = 0; i < lines / 2; ++i)
            f << "G3 X0 Y10 I-10 J0 Z" << -0.01 * i << " F800\nG2 X10 Y0 R10\n";
        f << "M30\n";
    }
    {
        std::ofstream f(loop);  // 1000 x 200 calls of a one-move subprogram
        f << "G65 P1 L1000\nM30\nO1\nG65 P2 L200\nM17\nO2\nG91 G1 X0.001 Y0.001 F1000\nM17\n";
    }
    measure("G1 X Y Z F surfacing", surf);
    measure("arcs (IJ helical, R)", arcs);
    measure("nested G65 200k calls", loop);
    ::unlink(surf.c_str());
    ::unlink(arcs.c_str());
    ::unlink(loop.c_str());
    return 0;
}
