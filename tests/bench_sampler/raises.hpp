// bench_sampler --raises (raises.cpp): how soon a jerk-limited feed-override increase takes
// effect, on a grid of instants over a plan.
#pragma once

namespace sampler_raises {
struct Options {
    bool short_grid = false;  // the few cases ctest runs
    // > 0: exit 1 if any raise starts rising later than this (ms after the request).
    double max_start_ms = 0;
};
// Prints the table; 1 if a run left the axis limits, a raise never got there, or a start came
// later than max_start_ms.
int raises_main(const Options& opt);
}  // namespace sampler_raises
