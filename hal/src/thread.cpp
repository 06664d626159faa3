#include "thread.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "runtime.hpp"
#include "segment.hpp"

namespace hal {

namespace {
std::int64_t monotonic_ns() noexcept {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}
timespec to_timespec(std::int64_t ns) noexcept {
    return timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}
template <class T>
void put(T& field, T v) noexcept {
    std::atomic_ref<T>(field).store(v, std::memory_order_relaxed);
}
template <class T>
T get(T& field) noexcept {
    return std::atomic_ref<T>(field).load(std::memory_order_relaxed);
}
// The s32 slot a timing pin points at now (link/unlink retarget it under the config lock).
std::int32_t* pin_slot(void*& field) noexcept {
    return static_cast<std::int32_t*>(std::atomic_ref<void*>(field).load(std::memory_order_relaxed));
}
}  // namespace

bool publish_time(void*& time_pin, Value& tmax, std::int64_t elapsed_ns) noexcept {
    const std::int32_t t = saturate_s32(elapsed_ns);
    put(*pin_slot(time_pin), t);
    const bool grew = t > get(tmax.s32);
    if (grew) put(tmax.s32, t);
    return grew;
}

int histogram_bucket(std::int64_t ns) noexcept {
    if (ns < 8) return ns < 0 ? 0 : static_cast<int>(ns);
    int bit = 63 - __builtin_clzll(static_cast<unsigned long long>(ns));
    int sub = static_cast<int>((ns >> (bit - 3)) & 7);
    int b = 8 + (bit - 3) * 8 + sub;
    return b < kHistogramBuckets ? b : kHistogramBuckets - 1;
}

std::int64_t histogram_bucket_floor(int bucket) noexcept {
    if (bucket < 8) return bucket;
    int bit = (bucket - 8) / 8 + 3;
    int sub = (bucket - 8) % 8;
    return (std::int64_t{8} + sub) << (bit - 3);
}

Thread::Thread(std::string name, std::int64_t period_ns, bool uses_fp, int cpu, ThreadStats* stats)
    : name_(std::move(name)), period_ns_(period_ns), uses_fp_(uses_fp), cpu_(cpu), stats_(stats) {
    lists_.push_back(std::make_unique<List>());
    active_.store(lists_.back().get());
}

Thread::~Thread() { stop(); }

std::int32_t Thread::time_ns() const noexcept {
    auto* slot = static_cast<std::int32_t*>(std::atomic_ref<void*>(time_pin_).load(std::memory_order_relaxed));
    return slot ? std::atomic_ref<std::int32_t>(*slot).load(std::memory_order_relaxed) : 0;
}

void Thread::set_functs(std::vector<Funct*> functs, const Segment& segment) {
    auto list = std::make_unique<List>();
    for (Funct* f : functs)
        list->entries.push_back({f->fn, f->object, segment.at<FunctTiming>(f->timing), &f->time_pin});
    // Group runs first (recording where each starts), then point them into the final array.
    std::vector<std::size_t> starts;
    for (std::size_t i = 0; i < functs.size(); ++i) {
        Funct* f = functs[i];
        bool extends = !list->runs.empty() && f->batch && list->runs.back().batch == f->batch;
        if (extends) {
            ++list->runs.back().count;
        } else {
            list->runs.push_back({f->fn, f->batch, nullptr, 1});
            starts.push_back(list->objects.size());
        }
        list->objects.push_back(f->object);
    }
    for (std::size_t r = 0; r < list->runs.size(); ++r) list->runs[r].objects = list->objects.data() + starts[r];
    functs_ = std::move(functs);
    active_.store(list.get(), std::memory_order_release);
    lists_.push_back(std::move(list));
    if (!running()) lists_.erase(lists_.begin(), lists_.end() - 1);
}

void Thread::run_functions(bool timed) noexcept {
    const List* list = active_.load(std::memory_order_acquire);
    const Period period = Period::from_ns(period_ns_);
    if (!timed) {
        for (const Run& r : list->runs) {
            if (r.count == 1) r.fn(r.objects[0], period);
            else r.batch(r.objects, r.count, period);
        }
        return;
    }
    std::int64_t t0 = monotonic_ns();
    for (const Entry& e : list->entries) {
        e.fn(e.object, period);
        std::int64_t t1 = monotonic_ns();
        put(e.timing->tmax_increased.b, publish_time(*e.time_pin, e.timing->tmax, t1 - t0));
        t0 = t1;
    }
}

void Thread::run_sim_cycle() noexcept {
    run_functions(false);
    put(stats_->cycles, get(stats_->cycles) + 1);
    next_deadline_ns += period_ns_;
}

std::string Thread::start(int priority) {
    if (running()) return {};
    std::string warning;
    keep_running_.store(true);
    os_thread_ = std::thread([this] { loop(); });
    pthread_setname_np(os_thread_.native_handle(), name_.substr(0, 15).c_str());
    if (priority > 0) {
        sched_param sp{};
        sp.sched_priority = priority;
        if (int rc = pthread_setschedparam(os_thread_.native_handle(), SCHED_FIFO, &sp); rc != 0)
            warning = fmt::format(
                "thread {}: SCHED_FIFO not permitted ({}); running with normal scheduling, "
                "expect larger wake-up errors",
                name_, std::strerror(rc));
    }
    if (cpu_ >= 0) {
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cpu_, &set);
        if (int rc = pthread_setaffinity_np(os_thread_.native_handle(), sizeof set, &set); rc != 0)
            warning += fmt::format("{}thread {}: cannot pin to cpu {} ({})", warning.empty() ? "" : "\n",
                                   name_, cpu_, std::strerror(rc));
    }
    return warning;
}

void Thread::stop() {
    if (!running()) return;
    keep_running_.store(false);
    os_thread_.join();
    lists_.erase(lists_.begin(), lists_.end() - 1);
}

void Thread::quiesce() const {
    if (!running()) return;
    const auto start = get(stats_->cycles);
    for (int i = 0; i < 2000 && get(stats_->cycles) < start + 2; ++i) {
        timespec ts{0, 500'000};
        nanosleep(&ts, nullptr);
    }
}

void Thread::loop() noexcept {
    std::int64_t deadline = monotonic_ns();
    std::uint64_t cycle = get(stats_->cycles);
    while (keep_running_.load(std::memory_order_relaxed)) {
        deadline += period_ns_;
        timespec ts = to_timespec(deadline);
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
        }
        const std::int64_t woke = monotonic_ns();
        const std::int64_t err = woke - deadline;
        put(stats_->wakeup_err_ns, err);
        if (err > get(stats_->wakeup_max_ns)) put(stats_->wakeup_max_ns, err);
        auto& bucket = stats_->histogram[histogram_bucket(err)];
        put(bucket, get(bucket) + 1);

        const std::uint64_t sample = get(stats_->funct_sample);
        run_functions(sample != 0 && cycle % sample == 0);
        ++cycle;
        put(stats_->cycles, cycle);

        const std::int64_t done = monotonic_ns();
        publish_time(time_pin_, stats_->tmax, done - woke);
        // Deadlines already past are skipped, not run back to back: a late cycle must not
        // turn into a burst of catch-up cycles.
        if (done >= deadline + period_ns_) {
            std::int64_t missed = (done - deadline) / period_ns_;
            deadline += missed * period_ns_;
            put(stats_->late_cycles, get(stats_->late_cycles) + static_cast<std::uint64_t>(missed));
        }
    }
}

}  // namespace hal
