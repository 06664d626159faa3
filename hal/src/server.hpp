// The instance socket: lets halcmd, userspace components and UIs talk to the owning
// process. One thread accepts; each connection gets a thread that runs its requests under
// the runtime's config mutex. Closing a connection removes the userspace component it made.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hal {

class Runtime;

class Server {
public:
    // `on_shutdown` runs (on a server thread) when a client asks the owner to exit.
    Server(Runtime& runtime, std::function<void()> on_shutdown);
    ~Server();
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

private:
    void accept_loop();
    void serve(int fd);

    Runtime& runtime_;
    std::function<void()> on_shutdown_;
    int listen_fd_ = -1;
    std::atomic<bool> stopping_{false};
    std::thread acceptor_;
    std::mutex mutex_;
    std::vector<std::thread> workers_;
    std::vector<int> client_fds_;
};

}  // namespace hal
