// BENCH FIXTURE ONLY, not the interpreter: reads the tiny G-code subset the planner benchmarks
// use (G0 G1 G2 G3 G17 G21 G90, X Y Z I J F, M2, comments) into planner segments, so the
// planner can be measured before the real interpreter exists. Anything else is rejected with
// file:line:col.
#pragma once

#include <string>
#include <vector>

#include "motion/types.hpp"

namespace motion::bench {

struct FixtureProgram {
    std::vector<PathSegment> segments;
    AxisArray start_mm{};
};

// tolerance_mm is applied to every move (G64 P). Throws std::runtime_error "file:line:col: why".
FixtureProgram read_ngc_fixture(const std::string& path, double tolerance_mm);

// Length of each programmed move (arc length for arcs), in order.
double programmed_length_mm(const PathSegment& seg, const AxisArray& start_mm);

}  // namespace motion::bench
