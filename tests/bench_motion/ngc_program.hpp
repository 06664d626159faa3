// Reads a G-code program through the real interpreter (interp::Interpreter + interp::Executor)
// and turns its canonical commands into planner segments, the way the motion component's sink
// does (components/motion/plan_sink.cpp), minus the HAL: motion/ itself stays interp-free.
#pragma once

#include <string>
#include <vector>

#include "motion/planner.hpp"
#include "motion/prepared.hpp"
#include "motion/types.hpp"

namespace motion::bench {

struct BenchProgram {
    std::vector<PathSegment> segments;
    AxisArray start_mm{};
    double dwell_s = 0;  // total G04 dwell time; the bench adds it to both motion time and bound
};

// default_tolerance_mm is the blend tolerance of every move until the program sets its own
// (G64 P; G61 = 0, exact path; G64 without P = back to the default); G09 stops at a move's
// end. Throws std::runtime_error "file:line:col: why" for a bad program.
BenchProgram read_program(const std::string& path, double default_tolerance_mm);

// Length of a programmed move starting at start_mm (arc length for arcs).
double programmed_length_mm(const PathSegment& seg, const AxisArray& start_mm);

// Every record the planner makes for the whole program, in order (planned ahead of time, as
// the benchmarks time the planner and the sampler separately).
std::vector<PreparedSegment> plan_all(const PlannerConfig& cfg, const BenchProgram& prog);

}  // namespace motion::bench
