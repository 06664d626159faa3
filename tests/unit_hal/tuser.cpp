// A userspace component for tests: registers `tuser` (or argv[1]) with an output pin set to
// 42 and an input pin it mirrors, reports ready, and runs until SIGTERM, as loadusr expects.
#include <csignal>
#include <thread>

#include <fmt/format.h>

#include "hal/client.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);
    std::string name = argc > 1 ? argv[1] : "tuser";
    try {
        hal::Client client(name);
        auto out = client.new_pin(name + ".out", hal::Type::S32, hal::Dir::Out);
        auto in = client.new_pin(name + ".in", hal::Type::S32, hal::Dir::In);
        auto echo = client.new_pin(name + ".echo", hal::Type::S32, hal::Dir::Out);
        hal::Value v;
        v.s32 = 42;
        out.set(v);
        client.ready();
        while (!g_stop) {
            echo.set(in.get());
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        return 0;
    } catch (const hal::Error& e) {
        fmt::print(stderr, "tuser: {}\n", e.what());
        return 1;
    }
}
