// Lock-free single-producer/single-consumer ring of trivially copyable records.
// The producer (planner thread) calls try_push; the consumer (servo thread) calls size, peek
// and pop. Storage is allocated once at construction; push/peek/pop never allocate or block.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <type_traits>

namespace motion {

template <class T>
class SpscRing {
    static_assert(std::is_trivially_copyable_v<T>);

  public:
    // capacity is rounded up to a power of two.
    explicit SpscRing(std::size_t capacity) {
        if (capacity < 2) throw std::invalid_argument("SpscRing capacity must be >= 2");
        std::size_t c = 1;
        while (c < capacity) c <<= 1;
        mask_ = c - 1;
        data_ = std::make_unique<T[]>(c);
    }

    std::size_t capacity() const noexcept { return mask_ + 1; }

    // Producer side.
    bool try_push(const T& v) noexcept {
        std::size_t t = tail_.load(std::memory_order_relaxed);
        if (t - head_.load(std::memory_order_acquire) > mask_) return false;
        data_[t & mask_] = v;
        tail_.store(t + 1, std::memory_order_release);
        return true;
    }
    std::size_t free_slots() const noexcept { return capacity() - size(); }

    // Consumer side.
    std::size_t size() const noexcept {
        return tail_.load(std::memory_order_acquire) - head_.load(std::memory_order_relaxed);
    }
    // The i-th record from the front; i < size().
    const T& peek(std::size_t i) const noexcept {
        return data_[(head_.load(std::memory_order_relaxed) + i) & mask_];
    }
    void pop() noexcept {
        head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
    }

  private:
    std::unique_ptr<T[]> data_;
    std::size_t mask_ = 0;
    alignas(64) std::atomic<std::size_t> head_{0};  // written by the consumer only
    alignas(64) std::atomic<std::size_t> tail_{0};  // written by the producer only
};

}  // namespace motion
