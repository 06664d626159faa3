#include "hal/client.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "ring.hpp"
#include "runtime.hpp"
#include "segment.hpp"

namespace hal {

std::string encode_request(const std::vector<std::string>& words) {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i) out += '\t';
        for (char c : words[i]) {
            if (c == '\\') out += "\\\\";
            else if (c == '\t') out += "\\t";
            else if (c == '\n') out += "\\n";
            else out += c;
        }
    }
    return out + "\n";
}

std::vector<std::string> decode_request(const std::string& line) {
    std::vector<std::string> words(1);
    for (std::size_t i = 0; i < line.size(); ++i) {
        char c = line[i];
        if (c == '\t') words.emplace_back();
        else if (c == '\\' && i + 1 < line.size()) {
            char n = line[++i];
            words.back() += n == 't' ? '\t' : n == 'n' ? '\n' : n;
        } else {
            words.back() += c;
        }
    }
    if (words.size() == 1 && words[0].empty()) words.clear();
    return words;
}

namespace {
int connect_socket(const std::string& path) {
    int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}
}  // namespace

bool Connection::running(const std::string& instance) {
    int fd = connect_socket(InstancePaths::for_instance(instance.empty() ? instance_from_env() : instance).socket_path);
    if (fd < 0) return false;
    ::close(fd);
    return true;
}

Connection::Connection(const std::string& instance)
    : instance_(instance.empty() ? instance_from_env() : instance) {
    auto paths = InstancePaths::for_instance(instance_);
    fd_ = connect_socket(paths.socket_path);
    if (fd_ < 0)
        throw Error(fmt::format("no HAL instance '{}' is running (start one with halrun)", instance_));
}

Connection::~Connection() {
    if (fd_ >= 0) ::close(fd_);
}

std::string Connection::request(const std::vector<std::string>& words) {
    auto msg = encode_request(words);
    for (std::size_t sent = 0; sent < msg.size();) {
        auto n = ::send(fd_, msg.data() + sent, msg.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) throw Error(fmt::format("lost connection to HAL instance '{}'", instance_));
        sent += static_cast<std::size_t>(n);
    }
    auto read_more = [&] {
        char buf[65536];
        auto n = ::recv(fd_, buf, sizeof buf, 0);
        if (n <= 0) throw Error(fmt::format("lost connection to HAL instance '{}'", instance_));
        buffer_.append(buf, static_cast<std::size_t>(n));
    };
    std::size_t nl;
    while ((nl = buffer_.find('\n')) == std::string::npos) read_more();
    std::string head = buffer_.substr(0, nl);
    auto space = head.find(' ');
    if (space == std::string::npos) throw Error("malformed reply from HAL instance");
    std::size_t len = std::stoull(head.substr(space + 1));
    while (buffer_.size() < nl + 1 + len) read_more();
    std::string body = buffer_.substr(nl + 1, len);
    buffer_.erase(0, nl + 1 + len);
    if (head.compare(0, space, "OK") != 0) throw Error(body);
    return body;
}

// ValueRef / StreamRef -------------------------------------------------------------------------

Value ValueRef::get() const noexcept {
    std::uint64_t off = offset_;
    if (is_pin_)
        off = reinterpret_cast<PinCell*>(base_ + offset_)->data_offset.load(std::memory_order_acquire);
    Value v;
    v.u64 = std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(base_ + off)).load(std::memory_order_relaxed);
    return v;
}

void ValueRef::set(Value v) noexcept {
    std::uint64_t off = offset_;
    if (is_pin_)
        off = reinterpret_cast<PinCell*>(base_ + offset_)->data_offset.load(std::memory_order_acquire);
    std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(base_ + off)).store(v.u64, std::memory_order_relaxed);
}

std::size_t StreamRef::fields() const noexcept { return ring_->fields; }
Type StreamRef::field_type(std::size_t i) const noexcept { return ring_->types[i]; }
bool StreamRef::push(const Value* r) noexcept { return ring_->push(r); }
bool StreamRef::pop(Value* r) noexcept { return ring_->pop(r); }
std::uint32_t StreamRef::depth() const noexcept { return ring_->depth; }
std::uint32_t StreamRef::used() const noexcept { return ring_->used(); }
std::uint64_t StreamRef::overruns() const noexcept { return ring_->overruns.load(); }

// Client -------------------------------------------------------------------------------------------

Client::Client(const std::string& component, const std::string& instance)
    : conn_(std::make_unique<Connection>(instance)) {
    auto seg = conn_->request({"@segment"});
    segment_ = Segment::attach(seg.substr(0, seg.find(' ')));
    if (!component.empty())
        component_id_ = std::stoi(conn_->request({"@comp", component, std::to_string(::getpid())}));
}

Client::~Client() = default;  // closing the connection removes the component

ValueRef Client::new_pin(const std::string& name, Type type, Dir dir) {
    if (component_id_ < 0) throw Error("new_pin needs a Client created with a component name");
    ValueRef r;
    r.type_ = type;
    r.base_ = segment_->base();
    r.offset_ = std::stoull(conn_->request({"@pin", std::to_string(component_id_), name,
                                            std::string(to_string(type)), std::to_string(static_cast<int>(dir))}));
    r.is_pin_ = true;
    return r;
}

ValueRef Client::new_param(const std::string& name, Type type, ParamDir dir) {
    if (component_id_ < 0) throw Error("new_param needs a Client created with a component name");
    ValueRef r;
    r.type_ = type;
    r.base_ = segment_->base();
    r.offset_ = std::stoull(conn_->request({"@param", std::to_string(component_id_), name,
                                            std::string(to_string(type)), std::to_string(static_cast<int>(dir))}));
    return r;
}

void Client::ready() { conn_->request({"@ready", std::to_string(component_id_)}); }

ValueRef Client::find(const std::string& name) {
    auto reply = conn_->request({"@lookup", name});
    char kind[16];
    char type[16];
    int dir;
    unsigned long long off;
    if (std::sscanf(reply.c_str(), "%15s %15s %d %llu", kind, type, &dir, &off) != 4)
        throw Error("malformed lookup reply");
    ValueRef r;
    r.type_ = *parse_type(type);
    r.base_ = segment_->base();
    r.offset_ = off;
    r.is_pin_ = std::string(kind) == "pin";
    return r;
}

StreamRef Client::stream(const std::string& name) {
    StreamRef s;
    s.ring_ = segment_->at<Ring>(std::stoull(conn_->request({"@stream", name})));
    if (s.ring_->magic != kRingMagic) throw Error(fmt::format("stream '{}' is damaged", name));
    return s;
}

}  // namespace hal
