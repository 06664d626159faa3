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
// The line - quarter arc - line plan of SamplerJerk.OverrideStepsAtEveryPointOfThePlan… (the
// motion tests), with every axis at 100 mm/s, 1000 mm/s^2 and `jerk` but Y weaker (600 mm/s^2,
// 0.4 of the jerk), so the arc and its joins use the limits unevenly.
motion::PlannerConfig line_arc_line_cfg(double jerk);
std::vector<motion::PreparedSegment> line_arc_line(const motion::PlannerConfig& cfg);
// The plan's duration at 100 %.
double planned_s(const std::vector<motion::PreparedSegment>& recs);
}  // namespace sampler_holds
