// Test support: seeded random programs for the planner property tests, the distance from a
// point to the programmed path, and a harness that streams a program through the planner, an
// SPSC ring and the sampler the way the motion component will, checking every servo period.
#pragma once

#include <functional>
#include <random>
#include <string>
#include <vector>

#include "motion/geometry.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"

namespace motion::test {

struct Program {
    AxisArray start{};
    std::vector<PathSegment> segs;  // segs[i].line == i
};

struct GenOptions {
    int count = 40;
    bool rotary = true;  // sometimes move A too
    // Mostly arcs (and some lines) meeting at kinks, each corner with a tolerance > 0 and no
    // exact stops: the corners with arcs that the planner blends.
    bool arc_corners = false;
    // Lines only, long (2-20 mm) and short (0.1-0.8 mm) at random, meeting at 30-130 degree
    // turns, each corner with a tolerance > 0, no exact stops or rapids: the corners next to a
    // short line that the planner cuts one-sided (one_sided_offset_corner).
    bool line_corners = false;
};

Program random_program(std::mt19937_64& rng, const GenOptions& opt);
AxisLimits random_limits(std::mt19937_64& rng, bool jerk);

// Programmed elements, one per segment (untrimmed), for distance checks.
std::vector<Element> programmed_elements(const Program& prog);
double distance_to(const Element& e, const AxisArray& p);

// What the harness does to the sampler while it runs: called before every period with the
// period index; may change override, hold or abort.
using Script = std::function<void(long period, Sampler& s)>;

struct PlayOptions {
    double dt_s = 1e-3;
    std::size_t ring_capacity = 64;
    int segments_per_period = 8;  // how fast the "planner thread" feeds
    long max_periods = 2'000'000;
    bool expect_done = true;
};

struct PlayReport {
    long periods = 0;
    bool done = false;
    bool aborted = false;
    bool starved = false;
    MotionSample last{};
    std::vector<MotionSample> samples;  // every period
    std::string violation;              // first limit/deviation/NaN violation, empty if none
};

// Streams prog through a Planner (cfg) into a ring and a Sampler, checking every sample
// against the limits (analytic and finite differences), the path tolerance and NaN.
PlayReport play(const PlannerConfig& cfg, const Program& prog, const Script& script,
                const PlayOptions& opt);

}  // namespace motion::test
