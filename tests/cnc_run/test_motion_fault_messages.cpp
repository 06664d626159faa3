// A fault of motion's servo function (a limit switch, a following-error trip, the e-stop)
// reaches the stream motion.messages while the machine is still loaded and running, not only
// when it is stopped: the end record with the fault's place and cause is there within 200 ms
// of wall time after the servo period that saw the fault, with the simulated clock not moved
// on in between (so within 0 ms of machine time), and it is sent once, also after `stop`.
// The motion component runs in a HAL instance of this process (hal::Runtime, simulated clock),
// so the test reads the stream while nothing is stopped. Figures by hand from the programs.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "interp/canon_wire.hpp"
#include "ring.hpp"
#include "runtime.hpp"
#include "scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr auto kLatencyBound = std::chrono::milliseconds(200);

// The program's error as motion sent it: place ("" for none, else "file:line" or
// "file:line:col") and cause.
struct EndRecord {
    std::string place;
    std::string cause;
};

class MotionMachine {
  public:
    // motion with `program` (written into a scratch folder), a 1 ms servo thread, enabled,
    // started. `setup` lines run before `start`.
    MotionMachine(const std::string& program, const std::vector<std::string>& setup = {}) {
        static int counter = 0;
        rt_ = std::make_unique<hal::Runtime>(
            hal::Runtime::Options{fmt::format("t-fault-msg-{}-{}", ::getpid(), ++counter),
                                  hal::kDefaultSegmentBytes, true});
        program_ = (scratch_.path() / "prog.ngc").string();
        std::ofstream(program_) << program;
        run(fmt::format("loadrt motion program={}", program_));
        run("loadrt threads name1=servo period1=1000000");
        run("addf motion-controller servo");
        run("setp motion.enable TRUE");
        for (const std::string& line : setup) run(line);
        run("start");
        ring_ = rt_->segment().at<hal::Ring>(rt_->stream_offset("motion.messages"));
    }
    ~MotionMachine() { rt_->shutdown(); }

    std::string run(const std::string& line) {
        std::vector<std::string> words;
        std::string w;
        for (char c : line + " ") {
            if (c != ' ') {
                w += c;
            } else if (!w.empty()) {
                words.push_back(w);
                w.clear();
            }
        }
        std::string out;
        rt_->execute(words, out);
        return out;
    }
    bool bit(const std::string& pin) { return run("getp " + pin).rfind("TRUE", 0) == 0; }
    const std::string& program() const { return program_; }

    // Takes what is on motion.messages now; true once an end record has been decoded.
    bool drain() {
        hal::Value v[interp::wire::kWireFields];
        while (ring_->pop(v)) {
            interp::wire::Record r;
            for (std::size_t i = 0; i < r.size(); ++i) r[i] = v[i].u64;
            if (decoder_.feed(r) != interp::wire::Decoder::Item::End) continue;
            ++ends_;
            if (!decoder_.failed()) continue;
            const auto& at = decoder_.error_loc();
            end_ = EndRecord{!at           ? ""
                             : at->col > 0 ? fmt::format("{}:{}:{}", at->file, at->line, at->col)
                                           : fmt::format("{}:{}", at->file, at->line),
                             decoder_.error_cause()};
        }
        return ends_ > 0;
    }
    // Waits (wall time, the simulated clock standing still) for the end record; how long it
    // took, or nullopt if none came within `bound`.
    std::optional<Clock::duration> await_end(Clock::duration bound) {
        const auto t0 = Clock::now();
        while (!drain()) {
            if (Clock::now() - t0 > bound) return std::nullopt;
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
        return Clock::now() - t0;
    }
    const std::optional<EndRecord>& end() const { return end_; }
    int ends() const { return ends_; }

  private:
    cnc_test::ScratchDir scratch_;
    std::string program_;
    std::unique_ptr<hal::Runtime> rt_;
    hal::Ring* ring_ = nullptr;
    interp::wire::Decoder decoder_;
    std::optional<EndRecord> end_;
    int ends_ = 0;
};

double ms(Clock::duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
}

// The fault's end record arrives on motion.messages within kLatencyBound (the wait is the test's
// latency_us property), with this place and cause.
void expect_end_record(MotionMachine& m, const std::string& place, const std::string& cause) {
    const auto latency = m.await_end(kLatencyBound);
    ASSERT_TRUE(latency) << "no end record on motion.messages within 200 ms of the fault";
    ::testing::Test::RecordProperty("latency_us", static_cast<int>(ms(*latency) * 1000));
    ASSERT_TRUE(m.end());
    EXPECT_EQ(m.end()->place, place);
    EXPECT_EQ(m.end()->cause, cause);
}

// The end record arrives before stop, within the bound; after stop and unload's reports
// nothing more is sent (one end record in all).
void expect_once_after_stop(MotionMachine& m) {
    m.run("advance 0.5");  // the fault stop runs out
    m.run("stop");
    m.drain();
    EXPECT_EQ(m.ends(), 1);
}

// X's positive limit switch closes in the middle of the G1 (100 mm/s from X0 to X100, line 2)
// 0.1 s in: a limit fault, which names no line (the switch is the machine's, whatever runs).
TEST(MotionFaultMessages, LimitSwitchTextArrivesWhileTheMachineRuns) {
    MotionMachine m("G90 G21\nG1 X100 F6000\nM30\n");
    m.run("advance 0.1");
    EXPECT_FALSE(m.drain()) << "an end record before any fault";
    m.run("setp joint.0.pos-lim-sw-in TRUE");
    m.run("advance 0.001");  // the servo period that sees the switch
    ASSERT_TRUE(m.bit("motion.fault"));
    expect_end_record(
        m, "",
        "joint 0 hit its positive limit switch (joint.0.pos-lim-sw-in); motion stopped, "
        "program abandoned");
    expect_once_after_stop(m);
}

// joint.0.motor-pos-fb is not connected (0), so joint 0's following error is its command.
// From rest at 990 mm/s^2 (1000 less the planner's 1 % override reserve; jerk unlimited) X is
// at 495 t^2 mm: 0.4757 mm after 31 periods, 0.50688 mm after 32, the first beyond
// max-ferror 0.5. The trip names the line running (2).
TEST(MotionFaultMessages, FollowingErrorTextNamesTheLineRunning) {
    MotionMachine m("G90 G21\nG1 X10 F6000\nM30\n", {"setp joint.0.max-ferror 0.5"});
    m.run("advance 0.032");
    ASSERT_TRUE(m.bit("motion.fault"));
    expect_end_record(
        m, m.program() + ":2",
        "joint 0 following error 0.5069 mm, over its limit joint.0.max-ferror = 0.5 mm; "
        "motion stopped, program abandoned");
    expect_once_after_stop(m);
}

// The program has ended (in position; the feeder has nothing more to plan) and the machine
// stays loaded: the e-stop (emc-enable-in dropped) is still published at once. Then once more
// after a stop and a start with the program long over.
TEST(MotionFaultMessages, EStopAfterTheProgramEndedArrivesWhileLoaded) {
    MotionMachine m("G90 G21\nG1 X10 F6000\nM30\n");
    m.run("advance 0.5");  // 0.2 s of motion
    ASSERT_TRUE(m.bit("motion.in-position"));
    m.run("stop");
    m.run("start");
    m.run("advance 0.01");
    EXPECT_FALSE(m.drain()) << "an end record before any fault";
    m.run("setp iocontrol.0.emc-enable-in FALSE");
    m.run("advance 0.001");
    ASSERT_TRUE(m.bit("motion.fault"));
    expect_end_record(
        m, "", "e-stop: iocontrol.0.emc-enable-in went FALSE; motion stopped, program abandoned");
    expect_once_after_stop(m);
}

// A G906 wait that times out (line 3, 0.5 s after the 0.2108 s move to X10 ends): the servo
// function's program error, at its line, before stop, and once.
TEST(MotionFaultMessages, WaitTimeoutArrivesBeforeStopAndOnce) {
    MotionMachine m("G90 G21\nG1 X10 F6000\nG906 PLC[0] LEVEL1 P500\nG1 X20\nM30\n");
    m.run("advance 0.72");
    ASSERT_TRUE(m.bit("motion.fault"));
    expect_end_record(m, m.program() + ":3",
                      "G906: motion.digital-in-00 did not become TRUE within 0.5 s");
    expect_once_after_stop(m);
}

}  // namespace
