// A fault of motion's servo function (a limit switch, a following-error trip, the e-stop)
// reaches the stream motion.messages while the machine is still loaded and running, not only
// when it is stopped: the end record with the fault's place and cause is there within 200 ms
// of wall time after the servo period that saw the fault, with the simulated clock not moved
// on in between (so within 0 ms of machine time), and it is sent once, also after `stop`.
// Also from an instance without program= (nothing to plan, so no planner thread), and for
// every fault, not only a load's first: each later one gets an end record of its own.
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
    // motion with `program` (written into a scratch folder; "": no program=), a 1 ms servo
    // thread, enabled, started. `setup` lines run before `start`.
    MotionMachine(const std::string& program, const std::vector<std::string>& setup = {}) {
        static int counter = 0;
        rt_ = std::make_unique<hal::Runtime>(
            hal::Runtime::Options{fmt::format("t-fault-msg-{}-{}", ::getpid(), ++counter),
                                  hal::kDefaultSegmentBytes, true});
        program_ = (scratch_.path() / "prog.ngc").string();
        std::ofstream(program_) << program;
        run(program.empty() ? std::string("loadrt motion")
                            : fmt::format("loadrt motion program={}", program_));
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
    bool drain() { return take() > 0; }
    // Takes what is on motion.messages now; the number of end records decoded so far.
    std::size_t take() {
        hal::Value v[interp::wire::kWireFields];
        while (ring_->pop(v)) {
            interp::wire::Record r;
            for (std::size_t i = 0; i < r.size(); ++i) r[i] = v[i].u64;
            if (decoder_.feed(r) != interp::wire::Decoder::Item::End) continue;
            const auto& at = decoder_.error_loc();
            ends_.push_back(EndRecord{!at ? ""
                                      : at->col > 0
                                          ? fmt::format("{}:{}:{}", at->file, at->line, at->col)
                                          : fmt::format("{}:{}", at->file, at->line),
                                      decoder_.failed() ? decoder_.error_cause() : "(not failed)"});
        }
        return ends_.size();
    }
    // Waits (wall time, the simulated clock standing still) for the n-th end record; how long
    // it took, or nullopt if it did not come within `bound`.
    std::optional<Clock::duration> await_end(Clock::duration bound, std::size_t n = 1) {
        const auto t0 = Clock::now();
        while (take() < n) {
            if (Clock::now() - t0 > bound) return std::nullopt;
            std::this_thread::sleep_for(std::chrono::microseconds(100));
        }
        return Clock::now() - t0;
    }
    // The last end record, if any.
    std::optional<EndRecord> end() const {
        return ends_.empty() ? std::nullopt : std::optional<EndRecord>(ends_.back());
    }
    std::size_t ends() const { return ends_.size(); }

  private:
    cnc_test::ScratchDir scratch_;
    std::string program_;
    std::unique_ptr<hal::Runtime> rt_;
    hal::Ring* ring_ = nullptr;
    interp::wire::Decoder decoder_;
    std::vector<EndRecord> ends_;
};

double ms(Clock::duration d) {
    return std::chrono::duration<double, std::milli>(d).count();
}

// The fault's end record (the n-th) arrives on motion.messages within kLatencyBound (the wait is
// the test's latency_us property), with this place and cause.
void expect_end_record(MotionMachine& m, const std::string& place, const std::string& cause,
                       std::size_t n = 1) {
    const auto latency = m.await_end(kLatencyBound, n);
    ASSERT_TRUE(latency) << "no end record " << n
                         << " on motion.messages within 200 ms of the fault";
    ::testing::Test::RecordProperty("latency_us", static_cast<int>(ms(*latency) * 1000));
    ASSERT_TRUE(m.end());
    EXPECT_EQ(m.end()->place, place);
    EXPECT_EQ(m.end()->cause, cause);
}

// The end records arrived before stop, within the bound; after stop and unload's reports
// nothing more is sent (`n` end records in all).
void expect_once_after_stop(MotionMachine& m, std::size_t n = 1) {
    m.run("advance 0.5");  // the fault stop runs out
    m.run("stop");
    m.take();
    EXPECT_EQ(m.ends(), n);
}

// Runs `setp` (an input that faults) and the one servo period that sees it; whether
// motion.fault is TRUE then.
bool trips(MotionMachine& m, const std::string& setp) {
    m.run(setp);
    m.run("advance 0.001");
    return m.bit("motion.fault");
}

// X's positive limit switch closes 0.1 s in: in the middle of the G1 (100 mm/s from X0 to X100,
// line 2), or, in an instance without program= and canon= (nothing to plan, so no planner
// thread; a thread of its own polls for faults from start to stop, where the old motion sent
// them only at stop), with the machine enabled at rest. A limit fault names no line (the
// switch is the machine's, whatever runs).
class LimitSwitchText : public ::testing::TestWithParam<const char*> {};

TEST_P(LimitSwitchText, ArrivesWhileTheMachineIsLoaded) {
    MotionMachine m(GetParam());
    m.run("advance 0.1");
    EXPECT_FALSE(m.drain()) << "an end record before any fault";
    ASSERT_TRUE(trips(m, "setp joint.0.pos-lim-sw-in TRUE"));
    expect_end_record(
        m, "",
        "joint 0 hit its positive limit switch (joint.0.pos-lim-sw-in); motion stopped, "
        "program abandoned");
    expect_once_after_stop(m);
}

INSTANTIATE_TEST_SUITE_P(MotionFaultMessages, LimitSwitchText,
                         ::testing::Values("G90 G21\nG1 X100 F6000\nM30\n", ""),
                         [](const auto& info) {
                             return std::string(*info.param ? "ProgramRunning" : "NoProgram");
                         });

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
    ASSERT_TRUE(trips(m, "setp iocontrol.0.emc-enable-in FALSE"));
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

// Each fault is sent, not only the first: a drive fault on X in the G1 (line 2, 0.1 s in), a
// limit switch of joint 1 during its stop ramp (from about 99 mm/s at 1000 mm/s^2, about
// 0.1 s: still running 2 ms later), and, after a reset (motion.enable falls and rises, the
// inputs clear), the e-stop. Three end records, each within the bound, in order; none again
// at stop.
TEST(MotionFaultMessages, EveryFaultIsSentNotOnlyTheFirst) {
    MotionMachine m("G90 G21\nG1 X100 F6000\nM30\n");
    m.run("advance 0.1");
    ASSERT_TRUE(trips(m, "setp joint.0.amp-fault-in TRUE"));
    expect_end_record(m, "",
                      "joint 0 drive fault (joint.0.amp-fault-in); motion stopped, program "
                      "abandoned");
    m.run("advance 0.002");
    ASSERT_GT(std::stod(m.run("getp motion.current-vel")), 1.0) << "the stop ramp is over";
    m.run("setp joint.1.neg-lim-sw-in TRUE");
    m.run("advance 0.001");
    expect_end_record(
        m, "",
        "joint 1 hit its negative limit switch (joint.1.neg-lim-sw-in); motion stopped, "
        "program abandoned",
        2);
    m.run("advance 0.2");
    m.run("setp joint.0.amp-fault-in FALSE");
    m.run("setp joint.1.neg-lim-sw-in FALSE");
    m.run("setp motion.enable FALSE");
    m.run("advance 0.001");
    m.run("setp motion.enable TRUE");
    m.run("advance 0.01");
    ASSERT_FALSE(m.bit("motion.fault")) << "not reset";
    EXPECT_EQ(m.take(), 2u) << "an end record without a fault";
    ASSERT_TRUE(trips(m, "setp iocontrol.0.emc-enable-in FALSE"));
    expect_end_record(
        m, "", "e-stop: iocontrol.0.emc-enable-in went FALSE; motion stopped, program abandoned",
        3);
    expect_once_after_stop(m, 3);
}

}  // namespace
