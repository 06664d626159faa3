#include "chain.hpp"

#include <fmt/format.h>

#include <sstream>

namespace bench {

std::vector<std::string> chain_commands(const ChainSpec& spec) {
    std::vector<std::string> cmds;
    cmds.push_back(fmt::format("loadrt threads name1={} period1={}", spec.thread, spec.period_ns));
    cmds.push_back(fmt::format("loadrt and2 count={}", spec.length));
    // Functions run in chain order, so a change at the head reaches the tail in one cycle.
    for (int i = 0; i < spec.length; ++i)
        cmds.push_back(fmt::format("addf and2.{} {}", i, spec.thread));
    for (int i = 0; i < spec.length; ++i) cmds.push_back(fmt::format("setp and2.{}.in1 1", i));
    cmds.push_back("setp and2.0.in0 1");
    for (int i = 0; i + 1 < spec.length; ++i)
        cmds.push_back(fmt::format("net chain-{} and2.{}.out and2.{}.in0", i, i, i + 1));
    return cmds;
}

std::vector<std::string> split_words(const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    return words;
}

}  // namespace bench
