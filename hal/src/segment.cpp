#include "segment.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "hal/types.hpp"

namespace hal {

namespace {
constexpr std::size_t kAlign = 16;
std::size_t round_up(std::size_t n) { return (n + kAlign - 1) & ~(kAlign - 1); }
}  // namespace

void validate_instance_name(const std::string& name) {
    if (name.empty() || name.size() > 64)
        throw Error(fmt::format("HAL instance name '{}' must be 1..64 characters", name));
    for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'))
            throw Error(fmt::format(
                "HAL instance name '{}' may only contain letters, digits, '-', '_' and '.'", name));
}

std::string instance_from_env() {
    const char* env = std::getenv("HAL_INSTANCE");
    std::string name = (env && *env) ? env : "default";
    validate_instance_name(name);
    return name;
}

InstancePaths InstancePaths::for_instance(const std::string& instance) {
    validate_instance_name(instance);
    InstancePaths p;
    p.instance = instance;
    p.shm_name = fmt::format("/cnchal.{}.{}", getuid(), instance);
    const char* dir = std::getenv("HAL_RUNTIME_DIR");
    std::string runtime_dir = (dir && *dir) ? dir : fmt::format("/tmp/cnchal-{}", getuid());
    ::mkdir(runtime_dir.c_str(), 0700);
    p.socket_path = fmt::format("{}/{}.sock", runtime_dir, instance);
    return p;
}

namespace {
// Fields of /proc/<pid>/stat after the command name, which may contain spaces and
// parentheses: field 3 (state) is the first.
std::vector<std::string> stat_fields(pid_t pid) {
    std::ifstream in(fmt::format("/proc/{}/stat", pid));
    std::string line;
    if (!std::getline(in, line)) return {};
    auto close = line.rfind(')');
    if (close == std::string::npos || close + 2 > line.size()) return {};
    std::istringstream stream(line.substr(close + 2));
    std::vector<std::string> fields;
    for (std::string f; stream >> f;) fields.push_back(f);
    return fields;
}
}  // namespace

std::uint64_t process_start_time(pid_t pid) {
    auto f = stat_fields(pid);
    return f.size() > 19 ? std::stoull(f[19]) : 0;  // field 22
}

bool process_alive(pid_t pid, std::uint64_t start_time) {
    if (pid <= 0) return false;
    auto f = stat_fields(pid);
    // A zombie (Z) or dead (X) owner no longer holds anything, even before it is reaped.
    if (f.empty() || f[0] == "Z" || f[0] == "X") return false;
    return f.size() > 19 && std::stoull(f[19]) == start_time;
}

std::unique_ptr<Segment> Segment::create(const InstancePaths& paths, std::size_t bytes,
                                         std::string* notice) {
    if (auto existing = [&]() -> std::unique_ptr<Segment> {
            try {
                return attach(paths.shm_name);
            } catch (const Error&) {
                return nullptr;
            }
        }()) {
        auto& h = existing->header();
        if (process_alive(h.owner_pid, h.owner_start_time))
            throw Error(fmt::format(
                "HAL instance '{}' is already running (pid {}); set HAL_INSTANCE to use another "
                "instance, or stop it with 'halrun -U'",
                paths.instance, h.owner_pid));
        if (notice)
            *notice = fmt::format("removed stale HAL instance '{}' left by dead process {}",
                                  paths.instance, h.owner_pid);
        existing.reset();
        ::shm_unlink(paths.shm_name.c_str());
        ::unlink(paths.socket_path.c_str());
    } else {
        ::shm_unlink(paths.shm_name.c_str());  // a segment too broken to attach
    }
    int fd = ::shm_open(paths.shm_name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0660);
    if (fd < 0)
        throw Error(fmt::format("cannot create shared memory {}: {}", paths.shm_name,
                                std::strerror(errno)));
    if (::ftruncate(fd, static_cast<off_t>(bytes)) != 0) {
        int e = errno;
        ::close(fd);
        ::shm_unlink(paths.shm_name.c_str());
        throw Error(fmt::format("cannot size shared memory to {} bytes: {}", bytes, std::strerror(e)));
    }
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
        int e = errno;
        ::close(fd);
        ::shm_unlink(paths.shm_name.c_str());
        throw Error(fmt::format("cannot map shared memory: {}", std::strerror(e)));
    }
    auto seg = std::unique_ptr<Segment>(new Segment(static_cast<std::byte*>(p), bytes, fd));
    auto* h = new (p) SegmentHeader{};
    h->abi = 1;
    h->header_bytes = static_cast<std::uint32_t>(round_up(sizeof(SegmentHeader)));
    h->size = bytes;
    h->brk.store(h->header_bytes);
    h->owner_pid = ::getpid();
    h->owner_start_time = process_start_time(::getpid());
    std::atomic_thread_fence(std::memory_order_release);
    h->magic = kSegmentMagic;  // last: an attacher never sees a half-made header as valid
    return seg;
}

std::unique_ptr<Segment> Segment::attach(const std::string& shm_name) {
    int fd = ::shm_open(shm_name.c_str(), O_RDWR, 0);
    if (fd < 0) throw Error(fmt::format("no shared memory {}: {}", shm_name, std::strerror(errno)));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) < sizeof(SegmentHeader)) {
        ::close(fd);
        throw Error(fmt::format("shared memory {} is not a HAL segment", shm_name));
    }
    auto bytes = static_cast<std::size_t>(st.st_size);
    void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
        int e = errno;
        ::close(fd);
        throw Error(fmt::format("cannot map {}: {}", shm_name, std::strerror(e)));
    }
    auto seg = std::unique_ptr<Segment>(new Segment(static_cast<std::byte*>(p), bytes, fd));
    if (seg->header().magic != kSegmentMagic)
        throw Error(fmt::format("shared memory {} is not a HAL segment (bad magic)", shm_name));
    return seg;
}

Segment::~Segment() {
    ::munmap(base_, size_);
    ::close(fd_);
}

std::uint64_t Segment::allocate(std::size_t bytes) {
    bytes = round_up(bytes ? bytes : 1);
    if (auto it = free_blocks_.find(bytes); it != free_blocks_.end()) {
        auto off = it->second;
        free_blocks_.erase(it);
        released_bytes_ -= bytes;
        std::memset(base_ + off, 0, bytes);
        return off;
    }
    auto& h = header();
    auto off = h.brk.load();
    if (off + bytes > size_)
        throw Error(fmt::format(
            "HAL shared memory full ({} bytes); start halrun with a larger HAL_SEGMENT_SIZE", size_));
    h.brk.store(off + bytes);
    return off;  // fresh tmpfs pages read as zero
}

void Segment::release(std::uint64_t offset, std::size_t bytes) {
    bytes = round_up(bytes ? bytes : 1);
    free_blocks_.emplace(bytes, offset);
    released_bytes_ += bytes;
}

std::size_t Segment::bytes_in_use() const noexcept {
    return header().brk.load() - released_bytes_;
}

}  // namespace hal
