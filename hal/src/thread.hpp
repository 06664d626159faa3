// A HAL thread: calls its functions once per period. In real-time mode an OS thread waits
// for absolute deadlines (clock_nanosleep TIMER_ABSTIME, SCHED_FIFO when permitted); in
// simulated-clock mode Runtime::advance steps it with no clock at all, so outputs are
// byte-identical run to run.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hal/component.hpp"

namespace hal {

struct Funct;
struct FunctTiming;
class Segment;

// Log-linear buckets: exact below 8 ns, then 8 per power of two (12.5 % resolution).
inline constexpr int kHistogramBuckets = 8 + 41 * 8;
int histogram_bucket(std::int64_t ns) noexcept;
std::int64_t histogram_bucket_floor(int bucket) noexcept;

// LinuxCNC publishes execution times as s32; ours are nanoseconds, which overflow an s32 past
// 2.147 s: such a time reads INT32_MAX rather than wrapping to a negative number.
constexpr std::int32_t saturate_s32(std::int64_t ns) noexcept {
    return ns > INT32_MAX ? INT32_MAX : ns < INT32_MIN ? INT32_MIN : static_cast<std::int32_t>(ns);
}
// Realtime: one measured execution time into a `.time` pin (whose current s32 slot `time_pin`
// points at) and its `.tmax` param, by LinuxCNC's rule (tmax follows the largest time seen);
// returns whether tmax grew, which is what `<funct>.tmax-increased` shows.
bool publish_time(void*& time_pin, Value& tmax, std::int64_t elapsed_ns) noexcept;

// Lives in the shared segment; each 8-byte field doubles as a param slot. The last execution
// time is the `<thread>.time` pin, not a field here (see Thread::time_pin_field).
struct ThreadStats {
    Value tmax;                    // s32 ns, saturated: max execution time (rw: write 0 to reset)
    std::int64_t wakeup_err_ns;    // last wake-up error (now - deadline)
    std::int64_t wakeup_max_ns;
    std::uint64_t late_cycles;     // deadlines missed and skipped, never replayed
    std::uint64_t cycles;
    std::uint64_t funct_sample;    // time every function every N cycles (0 = never)
    std::uint64_t histogram[kHistogramBuckets];  // wake-up error counts
};

class Thread {
public:
    Thread(std::string name, std::int64_t period_ns, bool uses_fp, int cpu, ThreadStats* stats);
    ~Thread();
    Thread(const Thread&) = delete;
    Thread& operator=(const Thread&) = delete;

    const std::string& name() const noexcept { return name_; }
    std::int64_t period_ns() const noexcept { return period_ns_; }
    bool uses_fp() const noexcept { return uses_fp_; }
    int cpu() const noexcept { return cpu_; }
    const std::vector<Funct*>& functs() const noexcept { return functs_; }
    ThreadStats& stats() const noexcept { return *stats_; }
    // The `<thread>.time` pin's current storage (s32 ns), retargeted through this field by
    // link/unlink; null until the runtime registers the pin.
    void** time_pin_field() noexcept { return &time_pin_; }
    std::int32_t time_ns() const noexcept;

    // Configuration world: replaces the function list; a running thread picks it up at its
    // next cycle (the old list stays alive until the thread stops).
    void set_functs(std::vector<Funct*> functs, const Segment& segment);

    // Real-time mode. `priority` 0 means normal scheduling. Returns a warning when
    // SCHED_FIFO or the CPU affinity could not be had.
    std::string start(int priority);
    void stop();
    // Returns once a running thread has begun a cycle with the current function list, so
    // an object removed from the list may be destroyed.
    void quiesce() const;
    bool running() const noexcept { return os_thread_.joinable(); }

    // Simulated-clock mode: the next deadline, and one cycle at it.
    std::int64_t next_deadline_ns = 0;
    void run_sim_cycle() noexcept;

private:
    struct Entry {
        RealtimeFn fn;
        void* object;
        struct FunctTiming* timing;
        void** time_pin;  // &Funct::time_pin
    };
    // A run of consecutive entries calling the same batchable function: one call for all.
    struct Run {
        RealtimeFn fn;
        RealtimeBatchFn batch;
        void* const* objects;
        std::size_t count;
    };
    struct List {
        std::vector<Entry> entries;  // one per function, for timed cycles
        std::vector<Run> runs;       // the same calls grouped, for every other cycle
        std::vector<void*> objects;  // the runs' object arrays
    };
    void loop() noexcept;
    void run_functions(bool timed) noexcept;

    std::string name_;
    std::int64_t period_ns_;
    bool uses_fp_;
    int cpu_;
    ThreadStats* stats_;
    mutable void* time_pin_ = nullptr;  // see time_pin_field()
    std::vector<Funct*> functs_;
    std::atomic<const List*> active_{nullptr};
    std::vector<std::unique_ptr<List>> lists_;  // current and retired lists
    std::atomic<bool> keep_running_{false};
    std::thread os_thread_;
};

}  // namespace hal
