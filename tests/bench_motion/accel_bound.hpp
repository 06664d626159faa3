// An acceleration-aware lower bound on the motion time of a program: no controller that follows
// the programmed path within each move's blend tolerance P (in order), keeps every axis within
// its velocity and acceleration limits and every feed move at or below its feed can finish
// sooner. Unlike sum(length / min(F, vmax)) it counts forced stops (program start and end, G09,
// dwells, corners under G61), the speed a corner of 90 degrees or more can be passed at within
// P, and the time an arc needs to turn each axis around at its extreme points.
// The argument is in docs/benchmarks.md ("The acceleration-aware lower bound"); XYZ programs
// only. The tolerance contract is the path-distance one: while the tool runs a move it stays
// within P of that move (not necessarily of the corner points), and it passes the moves in order.
#pragma once

#include <array>
#include <cstddef>

#include "motion/types.hpp"
#include "ngc_program.hpp"

namespace motion::bench {

struct AccelBoundResult {
    double time_s = 0;       // the bound, dwells included
    int capped_corners = 0;  // corners with a finite speed bound (not counting stops)
    int stops = 0;           // junctions that must be passed at rest (start and end too)
    int arc_windows = 0;     // arc extreme points that added turning time
};

// Throws std::runtime_error if the program moves an axis other than X, Y, Z.
AccelBoundResult accel_lower_bound(const BenchProgram& prog, const AxisLimits& lim);

// The bound's view of where the tool can be at the instant it passes corner `vertex` (0 = the
// program start; moves of no length do not count): an upper bound on max dir . (x - c) over the
// points x within P of both moves that meet at the corner c. 0 at the program's two ends. For
// tests of the corner-region step of the proof.
double corner_region_support_mm(const BenchProgram& prog, std::size_t vertex,
                                const std::array<double, 3>& dir);

}  // namespace motion::bench
