#include <fstream>

#include "backends.hpp"
#include "test_support.hpp"

namespace hal::test {
namespace {

// Records what the script sends to the bus instead of running it.
struct Recorder : Backend {
    std::vector<std::vector<std::string>> seen;
    void exec(const std::vector<std::string>& w, std::string& out) override {
        if (w[0] == "fail") throw Error("this command fails");
        seen.push_back(w);
    }
    std::vector<std::string> names(const std::string&) override { return {}; }
    bool component_exists(const std::string&) override { return false; }
    bool component_ready(const std::string&) override { return false; }
};

std::string temp_file(const std::string& name, const std::string& text) {
    auto path = fmt::format("{}/{}-{}", ::testing::TempDir(), ::getpid(), name);
    std::ofstream(path) << text;
    return path;
}

TEST(Script, TokenizesCommentsQuotesAndArrows) {
    Recorder r;
    Script s(r);
    EXPECT_EQ(s.tokenize("net a b => c  # comment"), (std::vector<std::string>{"net", "a", "b", "=>", "c"}));
    EXPECT_EQ(s.tokenize("echo \"two words\" x#y"), (std::vector<std::string>{"echo", "two words", "x#y"}));
    EXPECT_EQ(s.tokenize("   "), std::vector<std::string>{});
    EXPECT_THROW(s.tokenize("echo \"open"), Error);
}

TEST(Script, SubstitutesIniKeysAndEnvironment) {
    Recorder r;
    Script s(r);
    auto ini = temp_file("m.ini", "[JOINT_0]\nP = 1000\nFERROR=0.05\n[EMCMOT]\nSERVO_PERIOD = 1000000\n");
    s.load_ini(ini);
    ::setenv("CNC_TEST_VAR", "servo", 1);
    EXPECT_EQ(s.tokenize("setp pid.0.Pgain [JOINT_0]P"), (std::vector<std::string>{"setp", "pid.0.Pgain", "1000"}));
    EXPECT_EQ(s.tokenize("loadrt threads name1=$CNC_TEST_VAR period1=[EMCMOT]SERVO_PERIOD"),
              (std::vector<std::string>{"loadrt", "threads", "name1=servo", "period1=1000000"}));
    EXPECT_EQ(s.tokenize("echo $(CNC_TEST_VAR)-thread"), (std::vector<std::string>{"echo", "servo-thread"}));
    try {
        s.tokenize("setp x [JOINT_0]I");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), fmt::format("[JOINT_0]I is not in INI file '{}'", ini));
    }
    EXPECT_THROW(s.tokenize("echo $CNC_SURELY_UNSET_VARIABLE"), Error);
}

TEST(Script, JoinsContinuationsAndReportsFileAndLine) {
    Recorder r;
    Script s(r);
    auto hal = temp_file("a.hal", "# header\nnet sig \\\n  a.out \\\n  b.in\n\nfail now\nnet never x\n");
    testing::internal::CaptureStderr();
    EXPECT_FALSE(s.run_file(hal));
    EXPECT_EQ(testing::internal::GetCapturedStderr(), fmt::format("{}:6: this command fails\n", hal));
    ASSERT_EQ(r.seen.size(), 1u);  // stops at the failing line
    EXPECT_EQ(r.seen[0], (std::vector<std::string>{"net", "sig", "a.out", "b.in"}));
}

TEST(Script, SourceNestsAndRefusesCycles) {
    Recorder r;
    Script s(r);
    auto inner = temp_file("inner.hal", "setp x 1\n");
    auto outer = temp_file("outer.hal", fmt::format("source {}\nsetp y 2\n", inner));
    EXPECT_TRUE(s.run_file(outer));
    ASSERT_EQ(r.seen.size(), 2u);
    auto loop = fmt::format("{}/{}-loop.hal", ::testing::TempDir(), ::getpid());
    std::ofstream(loop) << "source " << loop << "\n";
    testing::internal::CaptureStderr();
    EXPECT_FALSE(s.run_file(loop));
    EXPECT_NE(testing::internal::GetCapturedStderr().find("sourced from itself"), std::string::npos);
}

TEST(Script, LoadusrWaitsForExitAndReportsFailure) {
    Recorder r;
    Script s(r);
    EXPECT_TRUE(s.run_line("loadusr -w true"));
    testing::internal::CaptureStderr();
    EXPECT_FALSE(s.run_line("loadusr -w false", "f.hal", 3));
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "f.hal:3: loadusr: 'false' failed (exit status 1)\n");
    EXPECT_TRUE(s.run_line("loadusr -w -i false"));
}

}  // namespace
}  // namespace hal::test
