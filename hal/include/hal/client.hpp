// The client library for processes other than the instance owner: halcmd, userspace
// components (loadusr), halsampler/halstreamer and user interfaces. Names are resolved
// through the instance socket once; values are then read and written directly in the
// shared segment, with no lock and no further messages.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/types.hpp"

namespace hal {

class Segment;
struct Ring;
struct PinCell;

// One request/response connection to an instance's owner.
class Connection {
public:
    // Connects to $HAL_INSTANCE (or `instance`); throws hal::Error naming the instance when
    // none is running.
    explicit Connection(const std::string& instance = "");
    ~Connection();
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;
    // Sends one command; returns its output or throws hal::Error with the owner's message.
    std::string request(const std::vector<std::string>& words);
    const std::string& instance() const noexcept { return instance_; }
    static bool running(const std::string& instance);

private:
    std::string instance_;
    int fd_ = -1;
    std::string buffer_;
};

// A pin, param or signal value in the segment, as another process sees it.
class ValueRef {
public:
    ValueRef() = default;
    Type type() const noexcept { return type_; }
    Value get() const noexcept;
    void set(Value v) noexcept;  // for pins owned by this process, params and writer-less signals

private:
    friend class Client;
    Type type_ = Type::Bit;
    std::byte* base_ = nullptr;
    std::uint64_t offset_ = 0;
    bool is_pin_ = false;  // follow the pin cell to wherever it is linked
};

// A stream endpoint in another process (halsampler reads, halstreamer writes).
class StreamRef {
public:
    std::size_t fields() const noexcept;
    Type field_type(std::size_t i) const noexcept;
    bool push(const Value* record) noexcept;
    bool pop(Value* record) noexcept;
    std::uint32_t depth() const noexcept;
    std::uint32_t used() const noexcept;
    std::uint64_t overruns() const noexcept;

private:
    friend class Client;
    Ring* ring_ = nullptr;
};

class Client {
public:
    // Attaches to the instance. With a component name, also registers a userspace component
    // that lives until this object is destroyed or the process exits.
    explicit Client(const std::string& component = "", const std::string& instance = "");
    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    ValueRef new_pin(const std::string& name, Type type, Dir dir);
    ValueRef new_param(const std::string& name, Type type, ParamDir dir);
    void ready();
    ValueRef find(const std::string& name);  // any pin, param or signal
    StreamRef stream(const std::string& name);
    Connection& connection() noexcept { return *conn_; }

private:
    std::unique_ptr<Connection> conn_;
    std::unique_ptr<Segment> segment_;
    int component_id_ = -1;
};

// Wire encoding of one request (words separated by tabs, with \t \n \\ escaped).
std::string encode_request(const std::vector<std::string>& words);
std::vector<std::string> decode_request(const std::string& line);

}  // namespace hal
