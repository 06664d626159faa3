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

#include "hal/ini.hpp"

namespace hal::test {
namespace {

TEST(Ini, ReadsLinuxCncStyleFiles) {
    auto ini = IniFile::parse(
        "# comment\n[EMC]\n  MACHINE = my mill   \nJUST WORDS WITHOUT EQUALS\n; other comment\n"
        "[HAL]\nHALFILE = a.hal\nHALFILE = b.hal\n[AXIS_X]\nMAX_VELOCITY = 100 \\\n   .5\nLIMIT = abc\n",
        "m.ini");
    EXPECT_EQ(ini.get("EMC", "MACHINE"), "my mill");
    EXPECT_EQ(ini.all("HAL", "HALFILE"), (std::vector<std::string>{"a.hal", "b.hal"}));
    EXPECT_EQ(ini.get("HAL", "HALFILE", 1), "b.hal");
    EXPECT_EQ(ini.get("AXIS_X", "MAX_VELOCITY"), "100 .5");
    EXPECT_FALSE(ini.get("EMC", "JUST WORDS WITHOUT EQUALS"));
    EXPECT_EQ(ini.find("AXIS_X", "LIMIT")->line, 12);
    try {
        ini.get_number("AXIS_X", "LIMIT");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "m.ini:12: [AXIS_X]LIMIT = 'abc' is not a number");
    }
    EXPECT_FALSE(ini.get_number("AXIS_Y", "LIMIT"));
}

TEST(Ini, IncludeContinuesTheSectionAndNamesItsFile) {
    auto part = temp_file("part.inc", "P = 7\n\nI = 2\n");
    auto main_ini = temp_file("main.ini", fmt::format("[JOINT_0]\n#INCLUDE {}\nD = 1\n", part));
    auto ini = IniFile::load(main_ini);
    EXPECT_EQ(ini.get("JOINT_0", "P"), "7");
    EXPECT_EQ(ini.get("JOINT_0", "D"), "1");
    EXPECT_EQ(ini.find("JOINT_0", "I")->file, part);
    EXPECT_EQ(ini.find("JOINT_0", "I")->line, 3);
    auto broken = temp_file("broken.ini", "[X]\n#INCLUDE /nonexistent/file.inc\n");
    try {
        IniFile::load(broken);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(fmt::format("{}:2: cannot open INI file '/nonexistent/file.inc'", broken)),
                  std::string::npos);
    }
}

TEST(Script, ParenthesizedKeysQuitAndAssignment) {
    Recorder r;
    Script s(r);
    s.load_ini(temp_file("p.ini", "[HOSTMOT2]\nBOARD = 5i25\n"));
    EXPECT_EQ(s.tokenize("loadrt hm2_[HOSTMOT2](BOARD)x"), (std::vector<std::string>{"loadrt", "hm2_5i25x"}));
    auto hal = temp_file("q.hal", "x.in = 3\nquit\nsetp never 1\n");
    EXPECT_TRUE(s.run_file(hal));
    ASSERT_EQ(r.seen.size(), 1u);
    EXPECT_EQ(r.seen[0], (std::vector<std::string>{"setp", "x.in", "3"}));
}

}  // namespace
}  // namespace hal::test
