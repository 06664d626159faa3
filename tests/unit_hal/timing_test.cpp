// LinuxCNC 2.9's timing objects (docs/linuxcnc-compat.md, R10): every thread and function has
// a `.time` s32 output pin and a `.tmax` s32 param, every function a `.tmax-increased` bit
// param. Ours hold nanoseconds, saturated at INT32_MAX. Real clock: the thread must run.
#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <climits>
#include <cstdint>
#include <thread>

#include "test_support.hpp"
#include "thread.hpp"

namespace hal::test {
namespace {

using Timing = RuntimeFixture;
using namespace std::chrono_literals;

std::int64_t as_s64(const std::string& s) {
    return std::stoll(s);
}

// A running thread with tspinner.0 timed on every cycle.
void start_spinner_thread(Timing& f) {
    f.make(false, "timing");
    f.run("loadrt threads name1=t period1=1000000");
    f.run("loadrt tspinner");
    f.run("addf tspinner.0 t");
    f.run("setp t.funct-sample 1");
    f.run("start");
}

// While it lives, the calling thread polls above the HAL threads' SCHED_FIFO priority (90)
// when it may: with every CPU busy in a real-time spin (other tests spinning beside this one)
// a normally scheduled poller would not run until the spins were over. Without permission the
// HAL threads are not SCHED_FIFO either, and nothing is changed.
class PollAboveHalThreads {
public:
    PollAboveHalThreads() {
        pthread_getschedparam(pthread_self(), &policy_, &param_);
        sched_param high{};
        high.sched_priority = 95;
        raised_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &high) == 0;
    }
    ~PollAboveHalThreads() {
        if (raised_) pthread_setschedparam(pthread_self(), policy_, &param_);
    }
    PollAboveHalThreads(const PollAboveHalThreads&) = delete;
    PollAboveHalThreads& operator=(const PollAboveHalThreads&) = delete;

private:
    int policy_ = SCHED_OTHER;
    sched_param param_{};
    bool raised_ = false;
};

// Stops the running thread inside a spin of `ns`: `stop` lets the cycle under way finish, so
// the spinning call is the thread's last one and its figures are what the pins and params show.
// On a loaded machine the poller may still miss a spin, or stop the thread a cycle late; both
// are seen and the spin is retried twice as long (so it still raises tmax).
bool stop_inside_spin(Timing& f, std::int64_t ns) {
    PollAboveHalThreads poll_first;
    for (int attempt = 0; attempt < 4; ++attempt, ns *= 2) {
        f.run(fmt::format("setp tspinner.0.spin-ns {}", ns));
        bool inside = false;
        const auto give_up = std::chrono::steady_clock::now() + 5s + std::chrono::nanoseconds(ns);
        while (std::chrono::steady_clock::now() < give_up) {
            if (f.run("getp tspinner.0.spinning") == "TRUE\n") {
                inside = true;
                break;
            }
            if (f.run("getp tspinner.0.spin-ns") == "0\n") break;  // missed: that spin is over
            std::this_thread::sleep_for(100us);
        }
        if (!inside) continue;
        f.run("stop");
        if (f.run("getp tspinner.0.calls") == f.run("getp tspinner.0.last-spin-call")) return true;
        f.run("start");
    }
    ADD_FAILURE() << "could not stop the thread inside a spin in 4 attempts";
    return false;
}

TEST_F(Timing, ThreadAndFunctionTimeArePinsThatNetToSignals) {
    make(false, "timing-net");
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tspinner");
    run("loadrt tprobe");
    run("addf tspinner.0 t");
    run("setp t.funct-sample 1");
    // As bench_hal feeds LinuxCNC: `net NAME <thread>.time <a reader>`.
    run("net thread-time t.time tprobe.0.in-s32");
    run("net funct-time tspinner.0.time");
    run("start");
    std::this_thread::sleep_for(50ms);
    run("stop");
    const auto thread_ns = as_s64(run("gets thread-time"));
    const auto funct_ns = as_s64(run("gets funct-time"));
    EXPECT_GT(thread_ns, 0);
    EXPECT_GT(funct_ns, 0);
    // Both come from the last cycle, and the thread's time spans its function's call.
    EXPECT_LE(funct_ns, thread_ns);
    EXPECT_LT(thread_ns, 1'000'000'000);  // nanoseconds, not seconds or clock ticks of a 1 ms cycle
    EXPECT_EQ(as_s64(run("getp tprobe.0.in-s32")), thread_ns);
    EXPECT_EQ(as_s64(run("getp t.time")), thread_ns);
    EXPECT_EQ(run("ptype t.time"), "s32\n");
    EXPECT_EQ(run("ptype tspinner.0.time"), "s32\n");
    EXPECT_NE(run("show pin t.time").find("s32   OUT"), std::string::npos);
    EXPECT_NE(error_of("setp t.time 5").find("is an output"), std::string::npos);
}

TEST_F(Timing, TmaxIncreasedMarksTheCallThatRaisedTmax) {
    start_spinner_thread(*this);
    std::this_thread::sleep_for(20ms);
    const auto tmax_before = as_s64(run("getp tspinner.0.tmax"));
    EXPECT_GT(tmax_before, 0);
    ASSERT_TRUE(stop_inside_spin(*this, 30'000'000));
    // The last call took >= 30 ms: it raised tmax, and .time is that call's.
    EXPECT_EQ(run("getp tspinner.0.tmax-increased"), "TRUE\n");
    const auto tmax = as_s64(run("getp tspinner.0.tmax"));
    EXPECT_GE(tmax, 30'000'000);
    EXPECT_GT(tmax, tmax_before);
    EXPECT_EQ(as_s64(run("getp tspinner.0.time")), tmax);
    EXPECT_GE(as_s64(run("getp t.tmax")), tmax);

    // Quick calls afterwards leave tmax alone and clear the flag (the runner does, each call).
    run("start");
    std::this_thread::sleep_for(20ms);
    run("stop");
    EXPECT_EQ(run("getp tspinner.0.tmax-increased"), "FALSE\n");
    EXPECT_EQ(as_s64(run("getp tspinner.0.tmax")), tmax);
    EXPECT_LT(as_s64(run("getp tspinner.0.time")), tmax);

    // tmax is RW (write 0 to restart it), tmax-increased is the runner's alone.
    run("setp tspinner.0.tmax 0");
    run("setp t.tmax 0");
    run("start");
    std::this_thread::sleep_for(20ms);
    run("stop");
    EXPECT_GT(as_s64(run("getp tspinner.0.tmax")), 0);
    EXPECT_LT(as_s64(run("getp tspinner.0.tmax")), tmax);
    EXPECT_LT(as_s64(run("getp t.tmax")), tmax);
    EXPECT_EQ(run("ptype tspinner.0.tmax"), "s32\n");
    EXPECT_EQ(run("ptype tspinner.0.tmax-increased"), "bit\n");
    EXPECT_NE(error_of("setp tspinner.0.tmax-increased 1").find("read-only"), std::string::npos);
}

// What the thread runner does with each measured time, on the numbers that matter: a real
// 2.2 s call would hold a CPU at SCHED_FIFO for 2.2 s and starve the tests running beside it.
TEST(PublishTime, SaturatesAndKeepsTmaxByLinuxcncsRule) {
    Value pin{};
    void* time_pin = &pin;
    Value tmax{};
    EXPECT_TRUE(publish_time(time_pin, tmax, 1'000));
    EXPECT_EQ(pin.s32, 1'000);
    EXPECT_EQ(tmax.s32, 1'000);
    EXPECT_FALSE(publish_time(time_pin, tmax, 400));  // shorter: tmax stays, time follows
    EXPECT_EQ(pin.s32, 400);
    EXPECT_EQ(tmax.s32, 1'000);
    EXPECT_FALSE(publish_time(time_pin, tmax, 1'000));         // equal is not an increase
    EXPECT_TRUE(publish_time(time_pin, tmax, 2'200'000'000));  // 2.2 s: past an s32 of ns
    EXPECT_EQ(pin.s32, INT32_MAX);
    EXPECT_EQ(tmax.s32, INT32_MAX);
    EXPECT_FALSE(publish_time(time_pin, tmax, 3'000'000'000));  // saturated both: no increase
    EXPECT_EQ(pin.s32, INT32_MAX);
    // The pin is followed through `time_pin`: a link moves where the time goes.
    Value signal{};
    time_pin = &signal;
    EXPECT_FALSE(publish_time(time_pin, tmax, 77));
    EXPECT_EQ(signal.s32, 77);
    EXPECT_EQ(pin.s32, INT32_MAX);
}

TEST(SaturateS32, ClampsInsteadOfWrapping) {
    EXPECT_EQ(saturate_s32(0), 0);
    EXPECT_EQ(saturate_s32(1'500'000), 1'500'000);
    EXPECT_EQ(saturate_s32(INT32_MAX), INT32_MAX);
    EXPECT_EQ(saturate_s32(std::int64_t{INT32_MAX} + 1), INT32_MAX);
    EXPECT_EQ(saturate_s32(2'200'000'000), INT32_MAX);  // a plain cast gives -2094967296
    EXPECT_EQ(saturate_s32(INT64_MAX), INT32_MAX);
    EXPECT_EQ(saturate_s32(std::int64_t{INT32_MIN} - 1), INT32_MIN);
}

TEST_F(Timing, TimePinsGoWithTheirThreadOrComponent) {
    make(false, "timing-remove");
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tspinner");
    run("addf tspinner.0 t");
    run("net thread-time t.time");
    run("net funct-time tspinner.0.time");
    run("start");
    std::this_thread::sleep_for(10ms);
    run("stop");
    run("delf tspinner.0 t");
    run("unload tspinner");
    EXPECT_NE(error_of("getp tspinner.0.time").find("tspinner.0.time"), std::string::npos);
    EXPECT_EQ(run("show sig funct-time").find("<=="), std::string::npos);  // no writer left
    run("delthread t");
    EXPECT_NE(error_of("getp t.time").find("t.time"), std::string::npos);
    EXPECT_NE(error_of("getp t.tmax").find("t.tmax"), std::string::npos);
    // The names are free again.
    run("loadrt threads name1=t period1=1000000");
    run("net thread-time t.time");
    EXPECT_EQ(run("gets thread-time"), "0\n");
}

TEST_F(Timing, SimulatedClockReadsNoClockSoTimesStayZero) {
    make(true, "timing-sim");
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tspinner");
    run("addf tspinner.0 t");
    run("net thread-time t.time");
    run("start");
    run("advance 0.01");
    EXPECT_EQ(run("gets thread-time"), "0\n");
    EXPECT_EQ(run("getp tspinner.0.time"), "0\n");
    EXPECT_EQ(run("getp tspinner.0.tmax"), "0\n");
    EXPECT_EQ(run("getp tspinner.0.tmax-increased"), "FALSE\n");
}

}  // namespace
}  // namespace hal::test
