// A component's non-realtime worker thread (an interpreter, a planner): the component's start()
// runs it and waits until it has reached a state worth starting the threads on; stop() pauses
// it by joining, and a later start() lets it go on where it was. Configuration world only;
// the realtime side never touches it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

namespace hal {

class Worker {
  public:
    Worker() = default;
    ~Worker() { pause_and_join(); }
    Worker(const Worker&) = delete;
    Worker& operator=(const Worker&) = delete;

    bool running() const noexcept { return thread_.joinable(); }

    // Runs `body` on a new thread and blocks until it calls mark_ready() (every body must, at
    // the latest when it returns). Returns the `failed` it passed.
    template <class Body>
    bool start_and_wait_ready(Body&& body) {
        pause_.store(false, std::memory_order_relaxed);
        {
            std::lock_guard lock(mutex_);
            ready_ = false;
        }
        thread_ = std::thread(std::forward<Body>(body));
        std::unique_lock lock(mutex_);
        ready_cv_.wait(lock, [this] { return ready_; });
        return failed_at_ready_;
    }

    // Asks the body to return (it polls pause_requested()) and joins it.
    void pause_and_join() {
        pause_.store(true, std::memory_order_relaxed);
        if (thread_.joinable()) thread_.join();
    }
    bool pause_requested() const noexcept { return pause_.load(std::memory_order_relaxed); }

    // From the body: start_and_wait_ready() may return, reporting `failed`. Only the first
    // call after a start counts, so the answer is decided at that moment.
    void mark_ready(bool failed) {
        std::lock_guard lock(mutex_);
        if (ready_) return;
        ready_ = true;
        failed_at_ready_ = failed;
        ready_cv_.notify_all();
    }

  private:
    std::thread thread_;
    std::atomic<bool> pause_{false};
    std::mutex mutex_;
    std::condition_variable ready_cv_;
    bool ready_ = false;
    bool failed_at_ready_ = false;
};

}  // namespace hal
