// Runs the benchmark chain on an installed LinuxCNC (2.9, uspace) and reads back the
// per-cycle thread execution time, so both runtimes are compared in the same run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "chain.hpp"

namespace bench {

struct LinuxcncOptions {
    std::string halrun = "/usr/bin/halrun";
    std::string modules_dir = "/usr/lib/linuxcnc/modules";
    int cycles = 3000;  // consecutive cycles recorded by LinuxCNC's own sampler
    int timeout_s = 120;
};

struct LinuxcncResult {
    bool ran = false;
    std::string why_not;           // set when !ran: what was missing or what LinuxCNC said
    std::vector<double> cycle_ns;  // servo-thread.time per cycle, converted to ns
    double tsc_hz = 0;             // LinuxCNC 2.9 uspace reports thread time in TSC ticks
    double tmax_ns = 0;            // servo-thread.tmax at the end of the run, converted to ns
    std::string rtapi_note;        // "POSIX non-realtime" or similar, from LinuxCNC's log
};

// Every sample of `servo-thread.time` is taken inside LinuxCNC by its `sampler` component
// (one record per cycle, written by the thread itself) and copied out by `halsampler`.
LinuxcncResult run_linuxcnc_chain(const ChainSpec& spec, const LinuxcncOptions& options);

// Ticks per second of the x86 time-stamp counter, calibrated against CLOCK_MONOTONIC.
// Returns 0 on other architectures.
double calibrate_tsc_hz();

}  // namespace bench
