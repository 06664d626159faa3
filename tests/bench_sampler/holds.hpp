// bench_sampler --holds (holds.cpp): the table of jerk-limited hold and override response times.
#pragma once

#include <vector>

#include "motion/planner.hpp"

namespace sampler_holds {
// The records a planner makes of `moves` (all of them, finished).
std::vector<motion::PreparedSegment> plan(const motion::PlannerConfig& cfg,
                                          const std::vector<motion::PathSegment>& moves);
// Prints the table; 1 if a run left the axis limits or a hold never ended.
int holds_main();
// The shortest stop from path speed u0 and tangential acceleration a0 under |a| <= acc and
// |jerk| <= jerk (at rest with a = 0): a lower bound for any hold from that state.
double shortest_stop_s(double u0, double a0, double acc, double jerk);
// When the plan of `recs` first reaches path speed `v_mm_s`, in ms of planned time (searched
// in 0.1 ms steps); the plan's whole length if it never does.
long reaches_ms(const std::vector<motion::PreparedSegment>& recs, double v_mm_s);
}  // namespace sampler_holds
