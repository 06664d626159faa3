// The shared-memory segment of one HAL instance: all bus storage (pin cells, params,
// signals, streams, thread statistics) lives here so other processes can read and write
// values without a lock. Names and wiring stay in the owning process (see runtime.hpp).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

namespace hal {

inline constexpr std::uint64_t kSegmentMagic = 0x434e43'48414c'31ULL;  // "CNCHAL1"
// Reserved, not committed: tmpfs allocates pages only when touched, so a large default
// lets 1000s of instances load without tuning. HAL_SEGMENT_SIZE overrides it.
inline constexpr std::size_t kDefaultSegmentBytes = 256u << 20;

struct SegmentHeader {
    std::uint64_t magic;
    std::uint32_t abi;
    std::uint32_t header_bytes;
    std::uint64_t size;
    std::atomic<std::uint64_t> brk;  // next free byte (bump allocation)
    std::int32_t owner_pid;
    std::uint64_t owner_start_time;  // /proc/<pid>/stat field 22: tells a reused pid apart
};

// Where an instance's files live: shm object name, socket path.
struct InstancePaths {
    std::string instance;
    std::string shm_name;  // "/cnchal.<uid>.<instance>"
    std::string socket_path;
    static InstancePaths for_instance(const std::string& instance);
};

// The instance name from $HAL_INSTANCE (default "default"), validated.
std::string instance_from_env();
void validate_instance_name(const std::string& name);

std::uint64_t process_start_time(pid_t pid);
bool process_alive(pid_t pid, std::uint64_t start_time);

class Segment {
public:
    // Creates the segment for `paths`; a segment left by a dead owner is removed first
    // (reported through `notice`), a live owner is an error.
    static std::unique_ptr<Segment> create(const InstancePaths& paths, std::size_t bytes,
                                           std::string* notice);
    static std::unique_ptr<Segment> attach(const std::string& shm_name);
    ~Segment();
    Segment(const Segment&) = delete;
    Segment& operator=(const Segment&) = delete;

    std::byte* base() const noexcept { return base_; }
    SegmentHeader& header() const noexcept { return *reinterpret_cast<SegmentHeader*>(base_); }
    std::size_t size() const noexcept { return size_; }
    template <class T = void>
    T* at(std::uint64_t offset) const noexcept {
        return reinterpret_cast<T*>(base_ + offset);
    }
    std::uint64_t offset_of(const void* p) const noexcept {
        return static_cast<std::uint64_t>(static_cast<const std::byte*>(p) - base_);
    }

    // Owner only, configuration world. Zero-filled storage; throws hal::Error when full.
    std::uint64_t allocate(std::size_t bytes);
    void release(std::uint64_t offset, std::size_t bytes);
    std::size_t bytes_in_use() const noexcept;

private:
    Segment(std::byte* base, std::size_t size, int fd) : base_(base), size_(size), fd_(fd) {}
    std::byte* base_;
    std::size_t size_;
    int fd_;
    std::multimap<std::size_t, std::uint64_t> free_blocks_;  // size -> offset, for reuse after unload
    std::size_t released_bytes_ = 0;
};

}  // namespace hal
