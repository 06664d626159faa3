// The benchmark's HAL configuration: a chain of `and2` instances in one thread, written in
// the HAL-file language both runtimes (ours and LinuxCNC's) accept unchanged.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace bench {

struct ChainSpec {
    int length = 1000;
    std::string thread = "servo-thread";
    std::int64_t period_ns = 1'000'000;
};

// One HAL command per element: the thread, the instances, their functions in chain order,
// every in1 held TRUE, and.i.out -> and2.(i+1).in0. Nothing is started.
std::vector<std::string> chain_commands(const ChainSpec& spec);

// Splits a command line into words the way the HAL language does for these plain lines.
std::vector<std::string> split_words(const std::string& line);

}  // namespace bench
