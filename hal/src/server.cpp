#include "server.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "hal/client.hpp"
#include "runtime.hpp"

namespace hal {

Server::Server(Runtime& runtime, std::function<void()> on_shutdown)
    : runtime_(runtime), on_shutdown_(std::move(on_shutdown)) {
    const auto& path = runtime_.paths().socket_path;
    ::unlink(path.c_str());
    listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof addr.sun_path) throw Error(fmt::format("socket path too long: {}", path));
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    if (listen_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listen_fd_, 16) != 0)
        throw Error(fmt::format("cannot listen on {}: {}", path, std::strerror(errno)));
    acceptor_ = std::thread([this] { accept_loop(); });
}

Server::~Server() {
    stopping_ = true;
    ::shutdown(listen_fd_, SHUT_RDWR);
    acceptor_.join();
    ::close(listen_fd_);
    {
        std::lock_guard lock(mutex_);
        for (int fd : client_fds_) ::shutdown(fd, SHUT_RDWR);
    }
    for (auto& w : workers_) w.join();
    ::unlink(runtime_.paths().socket_path.c_str());
}

void Server::accept_loop() {
    while (!stopping_) {
        pollfd p{listen_fd_, POLLIN, 0};
        if (::poll(&p, 1, 200) <= 0) continue;
        int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
        if (fd < 0) continue;
        std::lock_guard lock(mutex_);
        client_fds_.push_back(fd);
        workers_.emplace_back([this, fd] { serve(fd); });
    }
}

namespace {
bool send_all(int fd, const std::string& s) {
    for (std::size_t sent = 0; sent < s.size();) {
        auto n = ::send(fd, s.data() + sent, s.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) return false;
        sent += static_cast<std::size_t>(n);
    }
    return true;
}
}  // namespace

void Server::serve(int fd) {
    std::vector<int> owned_components;
    std::string buffer;
    char chunk[4096];
    bool open = true;
    while (open && !stopping_) {
        auto n = ::recv(fd, chunk, sizeof chunk, 0);
        if (n <= 0) break;
        buffer.append(chunk, static_cast<std::size_t>(n));
        std::size_t nl;
        while ((nl = buffer.find('\n')) != std::string::npos) {
            auto words = decode_request(buffer.substr(0, nl));
            buffer.erase(0, nl + 1);
            std::string out;
            bool ok = true;
            try {
                if (words.empty()) {
                } else if (words[0] == "@segment") {
                    out = fmt::format("{} {}", runtime_.paths().shm_name, runtime_.segment().size());
                } else if (words[0] == "@comp" && words.size() == 3) {
                    int id = runtime_.user_component(words[1], std::stoi(words[2]));
                    owned_components.push_back(id);
                    out = std::to_string(id);
                } else if ((words[0] == "@pin" || words[0] == "@param") && words.size() == 5) {
                    auto type = parse_type(words[3]);
                    if (!type) throw Error(fmt::format("bad type '{}'", words[3]));
                    int dir = std::stoi(words[4]);
                    out = std::to_string(words[0] == "@pin"
                                             ? runtime_.user_pin(std::stoi(words[1]), words[2], *type, static_cast<Dir>(dir))
                                             : runtime_.user_param(std::stoi(words[1]), words[2], *type,
                                                                   static_cast<ParamDir>(dir)));
                } else if (words[0] == "@ready" && words.size() == 2) {
                    runtime_.user_ready(std::stoi(words[1]));
                } else if (words[0] == "@lookup" && words.size() == 2) {
                    auto l = runtime_.lookup(words[1]);
                    out = fmt::format("{} {} {} {}", l.kind, to_string(l.type), l.dir, l.offset);
                } else if (words[0] == "@stream" && words.size() == 2) {
                    out = std::to_string(runtime_.stream_offset(words[1]));
                } else if (words[0] == "@names" && words.size() == 2) {
                    out = fmt::format("{}", fmt::join(words[1] == "command" ? runtime_.command_names()
                                                                            : runtime_.names(words[1]), "\n"));
                } else if (words[0] == "@exists" && words.size() == 2) {
                    out.assign(1, runtime_.component_exists(words[1]) ? '1' : '0');
                } else if (words[0] == "@isready" && words.size() == 2) {
                    out.assign(1, runtime_.component_ready(words[1]) ? '1' : '0');
                } else if (words[0] == "@shutdown") {
                    open = false;
                    if (on_shutdown_) on_shutdown_();
                } else {
                    runtime_.execute(words, out);
                }
            } catch (const std::exception& e) {
                ok = false;
                out = e.what();
            }
            if (!send_all(fd, fmt::format("{} {}\n", ok ? "OK" : "ERR", out.size()) + out)) open = false;
        }
    }
    for (int id : owned_components) runtime_.user_exit(id);
    std::lock_guard lock(mutex_);
    client_fds_.erase(std::remove(client_fds_.begin(), client_fds_.end(), fd), client_fds_.end());
    ::close(fd);
}

}  // namespace hal
