#pragma once
// A fixed-capacity vector stored inline: blocks are parsed millions of times per second, so the
// words of one block must never touch the heap.
#include <array>
#include <cstddef>
#include <initializer_list>

namespace interp {

template <typename T, std::size_t N>
class StaticVec {
  public:
    StaticVec() = default;
    StaticVec(std::initializer_list<T> init) {
        for (const T& v : init) push_back(v);
    }

    static constexpr std::size_t capacity() { return N; }
    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    bool full() const { return size_ == N; }

    // Returns false (and stores nothing) when full; the caller turns that into a located error.
    bool push_back(const T& v) {
        if (size_ == N) return false;
        items_[size_++] = v;
        return true;
    }
    void clear() { size_ = 0; }
    void erase_at(std::size_t i) {
        for (std::size_t k = i + 1; k < size_; ++k) items_[k - 1] = items_[k];
        --size_;
    }
    bool contains(const T& v) const {
        for (std::size_t i = 0; i < size_; ++i)
            if (items_[i] == v) return true;
        return false;
    }
    // Removes every element equal to v; returns whether any was removed.
    bool remove(const T& v) {
        bool found = false;
        for (std::size_t i = 0; i < size_;) {
            if (items_[i] == v) {
                erase_at(i);
                found = true;
            } else {
                ++i;
            }
        }
        return found;
    }

    T& operator[](std::size_t i) { return items_[i]; }
    const T& operator[](std::size_t i) const { return items_[i]; }
    T* begin() { return items_.data(); }
    T* end() { return items_.data() + size_; }
    const T* begin() const { return items_.data(); }
    const T* end() const { return items_.data() + size_; }

    friend bool operator==(const StaticVec& a, const StaticVec& b) {
        if (a.size_ != b.size_) return false;
        for (std::size_t i = 0; i < a.size_; ++i)
            if (!(a.items_[i] == b.items_[i])) return false;
        return true;
    }

  private:
    std::array<T, N> items_;  // not zeroed: only [0, size_) is ever read
    std::size_t size_ = 0;
};

}  // namespace interp
