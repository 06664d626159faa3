// halcmd: talks to a running HAL instance: one command from the command line, a file (-f),
// or an interactive prompt. With no instance running it starts one (halrun --serve) the
// way LinuxCNC's halcmd starts realtime; `halrun -U` stops it.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "backends.hpp"
#include "segment.hpp"

namespace {

void start_owner(const std::string& instance) {
    auto self = std::filesystem::read_symlink("/proc/self/exe");
    auto halrun = (self.parent_path() / "halrun").string();
    // The owner outlives this halcmd: it must not hold our terminal or pipes open, so its
    // output goes to a log beside the instance's socket.
    auto log = std::filesystem::path(hal::InstancePaths::for_instance(instance).socket_path).replace_extension(".log");
    pid_t pid = ::fork();
    if (pid == 0) {
        ::setsid();
        std::freopen("/dev/null", "r", stdin);
        std::freopen(log.c_str(), "w", stdout);
        std::freopen(log.c_str(), "a", stderr);
        execl(halrun.c_str(), "halrun", "--serve", "--instance", instance.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    for (int i = 0; i < 500; ++i) {
        if (hal::Connection::running(instance)) {
            fmt::print(stderr, "halcmd: started HAL instance '{}' (stop it with 'halrun -U'; its log: {})\n",
                       instance, log.string());
            return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    throw hal::Error(fmt::format("could not start HAL instance '{}' with {}", instance, halrun));
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"halcmd: send commands to a running HAL instance"};
    std::string file, ini, instance;
    bool keep_going = false, no_start = false;
    std::vector<std::string> command;
    app.add_option("-f,--file", file, "read commands from FILE ('-' for standard input)")->expected(0, 1);
    app.add_option("-i,--ini", ini, "INI file for [SECTION]KEY substitution");
    app.add_flag("-k,--keep-going", keep_going, "continue after a failing line");
    app.add_flag("--no-start", no_start, "fail instead of starting an instance");
    app.add_option("--instance", instance, "instance name (default $HAL_INSTANCE or 'default')");
    app.add_option("command", command, "one command and its arguments");
    app.allow_extras();
    CLI11_PARSE(app, argc, argv);
    for (auto& extra : app.remaining()) command.push_back(extra);

    try {
        if (instance.empty()) instance = hal::instance_from_env();
        setenv("HAL_INSTANCE", instance.c_str(), 1);
        if (!hal::Connection::running(instance)) {
            if (no_start) throw hal::Error(fmt::format("no HAL instance '{}' is running", instance));
            start_owner(instance);
        }
        hal::Connection conn(instance);
        hal::RemoteBackend backend(conn);
        hal::Script script(backend);
        if (!ini.empty()) script.load_ini(ini);

        if (!command.empty()) {
            std::string line;
            for (auto& w : command) line += (line.empty() ? "" : " ") + (w.find(' ') != std::string::npos ? "\"" + w + "\"" : w);
            return script.run_line(line, "halcmd") ? 0 : 1;
        }
        if (app.count("--file")) {
            if (file.empty() || file == "-") {
                std::string line;
                int n = 0, status = 0;
                while (std::getline(std::cin, line)) {
                    if (!script.run_line(line, "<stdin>", ++n)) {
                        status = 1;
                        if (!keep_going) break;
                    }
                }
                return status;
            }
            return script.run_file(file) ? 0 : 1;
        }
        hal::interactive(script, backend, "halcmd: ");
        return 0;
    } catch (const hal::Error& e) {
        fmt::print(stderr, "halcmd: {}\n", e.what());
        return 1;
    }
}
