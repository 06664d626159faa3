// halrun: owns a HAL instance. Runs a HAL file in a fresh instance and tears it down, or
// stays interactive (-I), or serves halcmd clients until stopped (--serve). -U cleans up
// an instance, live or left behind by a crash.
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include "backends.hpp"
#include "segment.hpp"
#include "server.hpp"

namespace {

int cleanup_instance(const std::string& instance) {
    auto paths = hal::InstancePaths::for_instance(instance);
    try {
        auto seg = hal::Segment::attach(paths.shm_name);
        auto& h = seg->header();
        if (hal::process_alive(h.owner_pid, h.owner_start_time)) {
            ::kill(h.owner_pid, SIGTERM);
            for (int i = 0; i < 500 && hal::process_alive(h.owner_pid, h.owner_start_time); ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            if (hal::process_alive(h.owner_pid, h.owner_start_time)) {
                fmt::print(stderr, "halrun: owner {} of instance '{}' did not exit; killing it\n", h.owner_pid, instance);
                ::kill(h.owner_pid, SIGKILL);
            }
        }
    } catch (const hal::Error&) {
        // No segment: nothing running; still remove a stray socket below.
    }
    ::shm_unlink(paths.shm_name.c_str());
    ::unlink(paths.socket_path.c_str());
    return 0;
}

std::atomic<bool> g_quit{false};
std::mutex g_quit_mutex;
std::condition_variable g_quit_cv;

void request_quit() {
    {
        std::lock_guard lock(g_quit_mutex);
        g_quit = true;
    }
    g_quit_cv.notify_all();
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"halrun: run a HAL file (or an interactive session) in a HAL instance of its own"};
    std::string file, ini, instance;
    bool interactive_mode = false, cleanup = false, sim_clock = false, serve = false;
    std::size_t segment_bytes = hal::kDefaultSegmentBytes;
    if (const char* env = std::getenv("HAL_SEGMENT_SIZE")) segment_bytes = std::stoull(env);
    app.add_option("file", file, "HAL file to run");
    app.add_option("-f,--file", file, "HAL file to run");
    app.add_option("-i,--ini", ini, "INI file for [SECTION]KEY substitution");
    app.add_flag("-I,--interactive", interactive_mode, "prompt for commands after the file");
    app.add_flag("-U,--cleanup", cleanup, "stop the instance and remove what it left behind");
    app.add_flag("-s,--sim-clock", sim_clock, "simulated clock: threads run only under 'advance'");
    app.add_flag("--serve", serve, "keep the instance running for halcmd until SIGTERM or halrun -U");
    app.add_option("--instance", instance, "instance name (default $HAL_INSTANCE or 'default')");
    app.add_option("--segment-size", segment_bytes, "shared memory to reserve, bytes");
    CLI11_PARSE(app, argc, argv);

    try {
        if (instance.empty()) instance = hal::instance_from_env();
        hal::validate_instance_name(instance);
        setenv("HAL_INSTANCE", instance.c_str(), 1);  // loadusr children attach to this instance
        if (cleanup) return cleanup_instance(instance);

        // Signals are taken by one thread so every other thread (realtime ones included)
        // runs undisturbed; the owner then shuts down in order.
        sigset_t set;
        sigemptyset(&set);
        sigaddset(&set, SIGINT);
        sigaddset(&set, SIGTERM);
        sigaddset(&set, SIGHUP);
        pthread_sigmask(SIG_BLOCK, &set, nullptr);
        std::thread([set] {
            int sig;
            sigwait(&set, &sig);
            request_quit();
            if (isatty(STDIN_FILENO)) ::close(STDIN_FILENO);  // ends an interactive prompt
        }).detach();

        hal::Runtime runtime({instance, segment_bytes, sim_clock});
        hal::Server server(runtime, request_quit);
        hal::LocalBackend backend(runtime);
        hal::Script script(backend);
        if (!ini.empty()) {
            script.load_ini(ini);
            // LinuxCNC's launcher exports the INI's path; HAL files pass it on as
            // $(INI_FILE_NAME) (e.g. halfiles/interp.hal), so `halrun -i` provides it too.
            if (!std::getenv("INI_FILE_NAME"))
                setenv("INI_FILE_NAME", std::filesystem::absolute(ini).c_str(), 1);
        }

        int status = 0;
        if (!file.empty() && !script.run_file(file)) status = 1;
        if (interactive_mode && !g_quit) {
            hal::interactive(script, backend, "halcmd: ");
        } else if (serve && status == 0) {
            std::unique_lock lock(g_quit_mutex);
            g_quit_cv.wait(lock, [] { return g_quit.load(); });
        }
        script.terminate_children();
        runtime.shutdown();
        return status;
    } catch (const hal::Error& e) {
        fmt::print(stderr, "halrun: {}\n", e.what());
        return 1;
    }
}
