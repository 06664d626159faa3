// Real-time threads, on the machine's real clock: late cycles are counted and skipped.
#include <chrono>
#include <thread>

#include "test_support.hpp"
#include "thread.hpp"

namespace hal::test {
namespace {

using ThreadRt = RuntimeFixture;

std::uint64_t as_u64(const std::string& s) { return std::stoull(s); }

TEST_F(ThreadRt, ALateCycleIsCountedNotReplayed) {
    make(false, "late");
    run("loadrt threads name1=t period1=1000000");
    run("loadrt tspinner");
    run("addf tspinner.0 t");
    run("start");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    // One call that takes 20 periods: the thread must skip the missed deadlines.
    auto calls_before = as_u64(run("getp tspinner.0.calls"));
    auto t0 = std::chrono::steady_clock::now();
    run("setp tspinner.0.spin-ns 20000000");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    auto calls_after = as_u64(run("getp tspinner.0.calls"));
    double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    run("stop");
    EXPECT_GE(as_u64(run("getp t.late-cycles")), 19u);
    // Replaying would run ~elapsed_ms calls; skipping runs about elapsed_ms - 20.
    EXPECT_LE(static_cast<double>(calls_after - calls_before), elapsed_ms - 15);
    EXPECT_GE(as_u64(run("getp t.tmax")), 20000000u);
}

TEST_F(ThreadRt, ThreadsPublishTimingInNanoseconds) {
    make(false, "timing");
    run("loadrt threads name1=t period1=500000");
    run("loadrt tprobe");
    run("addf tprobe.0 t");
    run("setp t.funct-sample 1");
    auto t0 = std::chrono::steady_clock::now();
    run("start");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    run("stop");
    double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    auto cycles = as_u64(run("getp t.cycles"));
    EXPECT_GE(cycles, 100u);  // 200 expected; a loaded CI machine may lose some
    EXPECT_LE(static_cast<double>(cycles), elapsed_ms * 2 + 1);  // never more than the deadlines passed
    EXPECT_GT(std::stoll(run("getp tprobe.0.tmax")), 0);
    EXPECT_LT(std::stoll(run("getp tprobe.0.tmax")), 50'000'000);
    auto show = run("show thread");
    EXPECT_NE(show.find("1 tprobe.0"), std::string::npos);
}

TEST(Histogram, BucketsAreOrderedAndTight) {
    std::int64_t last = -1;
    for (std::int64_t ns : {0LL, 1LL, 7LL, 8LL, 9LL, 15LL, 16LL, 1000LL, 123456LL, 999999999LL}) {
        int b = histogram_bucket(ns);
        EXPECT_LE(histogram_bucket_floor(b), ns);
        EXPECT_GT(histogram_bucket_floor(b + 1), ns);
        EXPECT_GE(histogram_bucket_floor(b), last);
        last = histogram_bucket_floor(b);
    }
    EXPECT_EQ(histogram_bucket(-5), 0);
}

}  // namespace
}  // namespace hal::test
