#include "linuxcnc.hpp"

#include <fmt/format.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

namespace bench {

namespace fs = std::filesystem;

namespace {

std::int64_t monotonic_ns() {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string tail_lines(const std::string& text, std::size_t n) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    std::string out;
    for (std::size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i)
        out += lines[i] + "\n";
    return out;
}

int run_shell(const std::string& command) {
    int status = std::system(command.c_str());
    if (status == -1) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// LinuxCNC's uspace realtime wants a non-root uid to drop to and a socket path it may
// create; the caller's own settings win.
void prepare_rtapi_env(const fs::path& dir) {
    if (!std::getenv("RTAPI_UID") && geteuid() == 0) setenv("RTAPI_UID", "65534", 1);
    if (!std::getenv("RTAPI_FIFO_PATH")) setenv("RTAPI_FIFO_PATH", (dir / "rtapi_fifo").c_str(), 1);
}

void write_hal_file(const fs::path& file, const fs::path& samples, const ChainSpec& spec,
                    int cycles) {
    std::ofstream out(file);
    for (const auto& line : chain_commands(spec)) out << line << '\n';
    // The sampler runs last in the thread, so each record is the previous cycle's time.
    out << "loadrt sampler depth=" << std::max(4096, cycles) << " cfg=s\n";
    out << "addf sampler.0 " << spec.thread << '\n';
    out << "net thread-time " << spec.thread << ".time sampler.0.pin.0\n";
    out << "start\n";
    out << "loadusr -w halsampler -n " << cycles << ' ' << samples.string() << '\n';
    out << "getp and2." << spec.length - 1 << ".out\n";
    out << "getp " << spec.thread << ".tmax\n";
}

}  // namespace

double calibrate_tsc_hz() {
#if defined(__x86_64__) || defined(__i386__)
    const std::int64_t t0 = monotonic_ns();
    const unsigned long long c0 = __rdtsc();
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const unsigned long long c1 = __rdtsc();
    const std::int64_t t1 = monotonic_ns();
    return static_cast<double>(c1 - c0) * 1e9 / static_cast<double>(t1 - t0);
#else
    return 0;
#endif
}

LinuxcncResult run_linuxcnc_chain(const ChainSpec& spec, const LinuxcncOptions& options) {
    LinuxcncResult r;
    if (!fs::exists(options.halrun) || !fs::exists(fs::path(options.modules_dir) / "and2.so")) {
        r.why_not = fmt::format("LinuxCNC not installed ({} or {}/and2.so missing)", options.halrun,
                                options.modules_dir);
        return r;
    }
    r.tsc_hz = calibrate_tsc_hz();
    if (r.tsc_hz <= 0) {
        r.why_not =
            "LinuxCNC reports thread time in CPU clocks; no TSC calibration on this architecture";
        return r;
    }
    char tmpl[] = "/tmp/halbench-linuxcnc-XXXXXX";
    if (!mkdtemp(tmpl)) {
        r.why_not = "cannot create a temporary directory";
        return r;
    }
    const fs::path dir = tmpl;
    ::chmod(dir.c_str(), 01777);  // the realtime drops to RTAPI_UID and must create its socket here
    prepare_rtapi_env(dir);
    const fs::path hal = dir / "chain.hal", samples = dir / "samples.txt", log = dir / "halrun.log";
    write_hal_file(hal, samples, spec, options.cycles);

    const int rc =
        run_shell(fmt::format("timeout {} {} -f {} > {} 2>&1 < /dev/null", options.timeout_s,
                              options.halrun, hal.string(), log.string()));
    const std::string log_text = read_text(log);
    if (log_text.find("POSIX non-realtime") != std::string::npos)
        r.rtapi_note = "LinuxCNC ran with POSIX non-realtime threads (kernel is not PREEMPT_RT)";
    if (rc != 0) {
        run_shell(fmt::format("timeout 30 {} -U > /dev/null 2>&1", options.halrun));
        r.why_not = fmt::format("LinuxCNC halrun exited with {}; last output:\n{}", rc,
                                tail_lines(log_text, 6));
        fs::remove_all(dir);
        return r;
    }
    const auto true_at = log_text.find("TRUE\n");
    if (true_at == std::string::npos) {
        r.why_not = "LinuxCNC chain did not propagate (tail of the chain is not TRUE)";
        fs::remove_all(dir);
        return r;
    }
    // `getp servo-thread.tmax` (TSC ticks) prints the first all-digit line after the TRUE;
    // LinuxCNC's notices may come in between.
    std::istringstream after(log_text.substr(true_at + 5));
    for (std::string line; std::getline(after, line);) {
        if (!line.empty() && line.find_first_not_of("0123456789") == std::string::npos) {
            r.tmax_ns = std::stod(line) * 1e9 / r.tsc_hz;
            break;
        }
    }
    std::ifstream in(samples);
    std::vector<double> ticks;
    for (long long v; in >> v;) ticks.push_back(static_cast<double>(v));
    // The first records predate a full cycle (0) or carry cold-cache start-up cycles.
    const std::size_t skip = ticks.size() / 10;
    for (std::size_t i = skip; i < ticks.size(); ++i)
        if (ticks[i] > 0) r.cycle_ns.push_back(ticks[i] * 1e9 / r.tsc_hz);
    fs::remove_all(dir);
    if (r.cycle_ns.empty()) {
        r.why_not = "halsampler returned no samples";
        return r;
    }
    r.ran = true;
    return r;
}

}  // namespace bench
