// Shared helpers: a Runtime in an instance of its own, loading test components.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <fmt/format.h>

#include "runtime.hpp"

namespace hal::test {

inline std::string unique_instance(const std::string& tag) {
    static int counter = 0;
    return fmt::format("ut-{}-{}-{}", tag, ::getpid(), ++counter);
}

inline std::vector<std::string> words(const std::string& line) {
    std::vector<std::string> out;
    std::string w;
    for (char c : line + " ") {
        if (c == ' ') {
            if (!w.empty()) out.push_back(w);
            w.clear();
        } else {
            w += c;
        }
    }
    return out;
}

struct RuntimeFixture : ::testing::Test {
    void SetUp() override { ::setenv("HAL_COMPONENT_PATH", TEST_COMPONENT_DIR, 1); }
    Runtime& make(bool sim_clock = true, const std::string& tag = "rt") {
        rt = std::make_unique<Runtime>(Runtime::Options{unique_instance(tag), kDefaultSegmentBytes, sim_clock});
        return *rt;
    }
    std::string run(const std::string& line) {
        std::string out;
        rt->execute(words(line), out);
        return out;
    }
    // The error message a command fails with ("" when it succeeds).
    std::string error_of(const std::string& line) {
        try {
            run(line);
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    }
    std::unique_ptr<Runtime> rt;
};

}  // namespace hal::test
