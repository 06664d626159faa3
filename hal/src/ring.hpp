// A stream's ring in the shared segment: single producer, single consumer, fixed-size
// records of 8-byte Values. Either side may be in another process; head and tail are the
// only shared mutable state and each has exactly one writer.
#pragma once

#include <atomic>
#include <cstdint>

#include "hal/types.hpp"

namespace hal {

inline constexpr std::uint32_t kRingMagic = 0x52494e47;  // "RING"
inline constexpr std::size_t kMaxStreamFields = 20;

struct Ring {
    std::uint32_t magic;
    std::uint32_t depth;     // records
    std::uint32_t fields;    // Values per record
    std::uint32_t reserved;
    Type types[kMaxStreamFields];
    alignas(64) std::atomic<std::uint64_t> head;  // written by the producer only
    alignas(64) std::atomic<std::uint64_t> tail;  // written by the consumer only
    alignas(64) std::atomic<std::uint64_t> overruns;  // producer: pushes refused, ring full
    std::atomic<std::uint64_t> underruns;              // consumer: pops refused, ring empty
    alignas(64) Value data[];  // depth * fields

    static std::size_t bytes_for(std::uint32_t depth, std::uint32_t fields) noexcept {
        return sizeof(Ring) + sizeof(Value) * std::size_t{depth} * fields;
    }
    bool push(const Value* record) noexcept {
        const auto h = head.load(std::memory_order_relaxed);
        if (h - tail.load(std::memory_order_acquire) >= depth) {
            overruns.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        Value* slot = data + (h % depth) * fields;
        for (std::uint32_t i = 0; i < fields; ++i) slot[i] = record[i];
        head.store(h + 1, std::memory_order_release);
        return true;
    }
    bool pop(Value* record) noexcept {
        const auto t = tail.load(std::memory_order_relaxed);
        if (head.load(std::memory_order_acquire) == t) {
            underruns.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        const Value* slot = data + (t % depth) * fields;
        for (std::uint32_t i = 0; i < fields; ++i) record[i] = slot[i];
        tail.store(t + 1, std::memory_order_release);
        return true;
    }
    std::uint32_t used() const noexcept {
        return static_cast<std::uint32_t>(head.load(std::memory_order_acquire) -
                                          tail.load(std::memory_order_acquire));
    }
};

// Parses a layout string ("ffb") into types; throws hal::Error naming the bad letter.
std::uint32_t parse_layout(std::string_view layout, Type* types);

}  // namespace hal
