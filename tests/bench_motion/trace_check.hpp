// Checks a recorded trace of commanded positions (one servo period per line, "X Y Z", as
// bench/linuxcnc/trace.hal + halsampler write it, or bench_motion --trace-out) against the
// programmed path and the axis limits: the largest distance from the path, and the largest
// per-axis velocity and acceleration from finite differences of the positions.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "motion/types.hpp"
#include "ngc_program.hpp"

namespace motion::bench {

struct TraceReport {
    long samples = 0;
    double max_deviation_mm = 0;
    std::int32_t deviation_line = 0;  // source line of the move nearest the worst sample
    long deviation_sample = 0;        // its index in the trace (0-based)
    double deviation_tolerance_mm = 0;  // the blend tolerance there (largest of the two moves)
    long samples_over_tolerance = 0;    // samples farther from the path than their tolerance
    // The same split by the kind of the nearest move: on rapids (G0) and on feed moves.
    double max_deviation_rapid_mm = 0, max_deviation_feed_mm = 0;
    long over_tolerance_rapid = 0, over_tolerance_feed = 0;
    // Source lines (nearest move) with samples beyond the tolerance: line -> largest distance.
    std::map<std::int32_t, double> over_by_line;
    std::array<double, 3> max_vel_mm_s{}, max_acc_mm_s2{};
    double max_speed_over_feed = 0;  // largest path speed / feed of the nearest feed move
    double end_error_mm = 0;
};

// Reads "x y z" lines (extra columns ignored). Throws std::runtime_error "file:line: why".
std::vector<std::array<double, 3>> read_trace(const std::string& path);

// period_s: the time between two lines. quantum_mm: the resolution of the recorded numbers;
// samples within tolerance + quantum count as within the tolerance.
TraceReport check_trace(const BenchProgram& prog, const std::vector<std::array<double, 3>>& trace,
                        double period_s, double quantum_mm);

}  // namespace motion::bench
