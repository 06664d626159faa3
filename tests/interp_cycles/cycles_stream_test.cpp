// Canned-cycle blocks with many holes stream: the executor makes each hole's commands only when
// the previous hole has been passed on, so `K1000000` or a 9999×9999 G37 grid runs in flat
// memory. This binary counts the heap bytes it has live (operator new/delete below), so the
// tests can assert on the peak growth while a block runs; an eager expansion of the same blocks
// would need hundreds of megabytes (≈ 4 commands × ~100 bytes per hole).
// GCC pairs the std::malloc inside operator new below with the sized delete of the allocators
// and warns; both sides are this file's, so the pairing is right.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

#include "interp/canon.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/source.hpp"

namespace heap {
std::atomic<long long> live_bytes{0};
std::atomic<long long> peak_bytes{0};

void note_alloc(void* p) {
    if (p == nullptr) return;
    const long long now =
        live_bytes.fetch_add(static_cast<long long>(malloc_usable_size(p))) +
        static_cast<long long>(malloc_usable_size(p));
    long long peak = peak_bytes.load();
    while (now > peak && !peak_bytes.compare_exchange_weak(peak, now)) {
    }
}
void note_free(void* p) {
    if (p != nullptr) live_bytes.fetch_sub(static_cast<long long>(malloc_usable_size(p)));
}
void reset_peak() {
    peak_bytes.store(live_bytes.load());
}
}  // namespace heap

void* operator new(std::size_t n) {
    void* p = std::malloc(n == 0 ? 1 : n);
    if (p == nullptr) throw std::bad_alloc();
    heap::note_alloc(p);
    return p;
}
void* operator new[](std::size_t n) {
    void* p = std::malloc(n == 0 ? 1 : n);
    if (p == nullptr) throw std::bad_alloc();
    heap::note_alloc(p);
    return p;
}
void operator delete(void* p) noexcept {
    heap::note_free(p);
    std::free(p);
}
void operator delete[](void* p) noexcept {
    heap::note_free(p);
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    heap::note_free(p);
    std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
    heap::note_free(p);
    std::free(p);
}

namespace {

struct StopSink : std::exception {};

// Counts commands; remembers the last traverse; throws after `limit` commands (0 = never).
class CountingSink : public interp::CanonSink {
  public:
    explicit CountingSink(long limit = 0) : limit_(limit) {}
    void emit(const interp::Canon& c) override {
        ++count;
        if (const auto* t = std::get_if<interp::canon::Traverse>(&c.cmd)) last_traverse = t->end_mm;
        if (std::holds_alternative<interp::canon::FeedLine>(c.cmd)) ++feeds;
        if (limit_ > 0 && count >= limit_) throw StopSink();
    }
    long count = 0;
    long feeds = 0;
    interp::AxisVec last_traverse{};

  private:
    long limit_;
};

// Runs `program` to its end or until the sink throws; returns the peak heap growth in bytes.
long long run_program(const std::string& program, interp::CanonSink& sink) {
    interp::BackendConfig cfg;
    interp::Executor exec(sink, cfg);
    interp::Interpreter in(exec, exec, interp::InterpreterOptions{});
    in.open(interp::Source::from_string("stream.nc", program));
    heap::reset_peak();
    const long long base = heap::live_bytes.load();
    try {
        in.run();
    } catch (const StopSink&) {
    }
    return heap::peak_bytes.load() - base;
}

constexpr long long kFlatBytes = 1 << 20;  // 1 MiB: a few holes' worth, never the whole block

TEST(CycleStream, MillionRepeatsUnderG91RunInFlatMemory) {
    // G91 K1000000: equally spaced holes 1 mm apart in X (CC-10). From Z10, R-5 → R plane 5,
    // Z-5 → bottom 0; G98 returns every hole to the initial level Z10, so each hole is exactly
    // 4 commands: rapid over the hole, rapid to R, feed to Z, rapid back to Z10.
    CountingSink sink;
    const long long growth =
        run_program("G00 X0 Y0 Z10\nG91 G81 X1 Z-5 R-5 F100 K1000000\nG80\nM30\n", sink);
    EXPECT_EQ(sink.feeds, 1000000);
    EXPECT_DOUBLE_EQ(sink.last_traverse[0], 1000000.0);
    EXPECT_DOUBLE_EQ(sink.last_traverse[2], 10.0);
    EXPECT_LT(growth, kFlatBytes) << "peak heap growth " << growth << " bytes";
}

TEST(CycleStream, HoleCommandsReachTheSinkBeforeTheNextHoleIsMade) {
    // The sink gives up after 1000 commands of a 99999999-hole block: with lazy holes the block
    // stops at once and has allocated next to nothing; an eager block would first have built
    // all 400 million commands.
    CountingSink sink(1000);
    const long long growth =
        run_program("G00 X0 Y0 Z10\nG91 G81 X1 Z-5 R-5 F100 K99999999\n", sink);
    EXPECT_EQ(sink.count, 1000);
    EXPECT_LT(growth, kFlatBytes);
}

TEST(CycleStream, HugeG37GridIsGeneratedHoleByHole) {
    // G37 with 9999 × 9999 holes (SC-9 maximum): 99980001 holes, never listed.
    CountingSink sink(2000);
    const long long growth = run_program(
        "G00 X0 Y0 Z10\nG81 Z-1 R2 F100 K0\nG37 X0 Y0 I1 P9999 J1 K9999\n", sink);
    EXPECT_EQ(sink.count, 2000);
    EXPECT_LT(growth, kFlatBytes);
    // Serpentine: the first row runs +X from X0, so after ~500 holes the tool is still in it.
    EXPECT_DOUBLE_EQ(sink.last_traverse[1], 0.0);
    EXPECT_GT(sink.last_traverse[0], 400.0);
}

TEST(CycleStream, AStopInTheSameBlockComesAfterEveryHole) {
    // M00 in a K3 block: the stop follows the third hole, not the first.
    class Recorder : public interp::CanonSink {
      public:
        void emit(const interp::Canon& c) override { lines.push_back(interp::to_text(c)); }
        std::vector<std::string> lines;
    } rec;
    run_program("G00 X0 Y0 Z10\nG91 G81 X1 Z-5 R-5 F100 K3 M00\nM30\n", rec);
    const auto stop = std::find(rec.lines.begin(), rec.lines.end(), "2 stop");
    ASSERT_NE(stop, rec.lines.end());
    ASSERT_NE(stop, rec.lines.begin());
    EXPECT_EQ(*(stop - 1), "2 traverse X3 Y0 Z10");  // the third hole's return to Z10
    EXPECT_EQ(std::count_if(rec.lines.begin(), stop,
                            [](const std::string& l) { return l.rfind("2 feed ", 0) == 0; }),
              3);
}

}  // namespace
