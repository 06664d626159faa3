// `cnc run`: the product's main job. Loads an INI, runs its [HAL]HALFILEs in a HAL instance
// owned by this process, names the program to the config (environment variable CNC_PROGRAM,
// which the config's `loadrt interp program=$(CNC_PROGRAM)` reads; the interp component
// streams its canonical commands to motion), starts the threads and watches motion's pins
// until the program ends (interp.done and motion.in-position), a fault, a timeout or Ctrl-C.
//
// Two clocks: the real one (the HAL threads run on their own; a sampler stream hands this loop
// every cycle's pins) and --sim-clock (this loop advances the simulated clock one servo period
// at a time and reads the pins, so the output is the same on every run).
#include "run.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "../../components/machine_program_ini.hpp"
#include "backends.hpp"
#include "hal/ini.hpp"
#include "hal/script.hpp"
#include "interp/block.hpp"
#include "interp/canon_wire.hpp"
#include "interp/persist.hpp"
#include "preview.hpp"
#include "ring.hpp"
#include "runtime.hpp"
#include "segment.hpp"

namespace cncrun {
namespace {

namespace fs = std::filesystem;

constexpr double kPollPeriodS = 0.005;  // real-time clock: how often the pins are read
constexpr double kEnableGraceS = 1.0;   // the machine must be enabled within this
constexpr double kAbortGraceS = 10.0;   // after Ctrl-C: time allowed for the stop ramp
constexpr double kTtyRedrawS = 0.1;     // progress bar redraw interval, wall time
// A fault at rest whose cause has not arrived on motion.messages yet: how long (wall time) to
// wait for it before `stop`. motion sends it within a millisecond or so of the fault; under
// --sim-clock the machine can come to rest in less wall time than that.
constexpr double kFaultTextWaitS = 1.0;
constexpr int kBarWidth = 30;

// Ctrl-C, SIGTERM and SIGHUP are taken by one waiter thread, so the HAL threads (which
// inherit the blocked mask) run undisturbed. The first request asks for a controlled stop;
// a second one quits at once. Construct before the runtime so its threads inherit the mask.
class StopRequest {
  public:
    StopRequest() {
        sigemptyset(&set_);
        for (int s : {SIGINT, SIGTERM, SIGHUP, SIGUSR1}) sigaddset(&set_, s);
        pthread_sigmask(SIG_BLOCK, &set_, nullptr);
        waiter_ = std::thread([this] { wait(); });
    }
    ~StopRequest() {
        pthread_kill(waiter_.native_handle(), SIGUSR1);  // SIGUSR1 only ends the waiter
        waiter_.join();
    }
    StopRequest(const StopRequest&) = delete;
    StopRequest& operator=(const StopRequest&) = delete;
    bool requested() const noexcept { return requested_.load(std::memory_order_relaxed); }
    // The shared-memory segment to remove if a second request quits at once (a normal end
    // removes it through the runtime). Set once, before the run starts.
    void set_segment_on_quit(const std::string& shm_name) {
        shm_name_ = shm_name;
        segment_known_.store(true, std::memory_order_release);
    }

  private:
    void wait() {
        for (;;) {
            int sig = 0;
            sigwait(&set_, &sig);
            if (sig == SIGUSR1) return;
            if (!requested_.exchange(true)) continue;
            if (segment_known_.load(std::memory_order_acquire)) ::shm_unlink(shm_name_.c_str());
            std::_Exit(130);
        }
    }
    sigset_t set_{};
    std::atomic<bool> requested_{false};
    std::string shm_name_;
    std::atomic<bool> segment_known_{false};
    std::thread waiter_;
};

// A pin, param or signal read straight from the segment, without the runtime's lock: the HAL
// threads write these while the loop reads them (every slot is one relaxed 8-byte access).
class Probe {
  public:
    Probe(hal::Runtime& rt, const std::string& name)
        : seg_(&rt.segment()), lookup_(rt.lookup(name)) {}
    double number() const noexcept {
        const hal::Value v = read();
        switch (lookup_.type) {
            case hal::Type::Bit:
                return v.b ? 1.0 : 0.0;
            case hal::Type::Float:
                return v.f;
            case hal::Type::S32:
                return v.s32;
            case hal::Type::U32:
                return v.u32;
            case hal::Type::S64:
                return static_cast<double>(v.s64);
            case hal::Type::U64:
                return static_cast<double>(v.u64);
        }
        return 0;
    }
    bool bit() const noexcept { return number() != 0; }

  private:
    hal::Value read() const noexcept {
        std::uint64_t offset = lookup_.offset;
        if (lookup_.kind == "pin")
            offset = seg_->at<hal::PinCell>(offset)->data_offset.load(std::memory_order_acquire);
        const std::uint64_t raw = std::atomic_ref<std::uint64_t>(*seg_->at<std::uint64_t>(offset))
                                      .load(std::memory_order_relaxed);
        hal::Value v;
        std::memcpy(&v, &raw, sizeof v);
        return v;
    }
    hal::Segment* seg_;
    hal::Runtime::Lookup lookup_;
};

std::optional<Probe> try_probe(hal::Runtime& rt, const std::string& name) {
    try {
        return Probe(rt, name);
    } catch (const hal::Error&) {
        return std::nullopt;
    }
}

// What the run needs from the INI, checked before anything is loaded.
struct Config {
    std::vector<std::string> hal_files;  // resolved against the INI's folder
    double period_s = 0;
    std::string axis_letters;  // lower case, once each, in [TRAJ]COORDINATES order
    int program_lines = 0;
    std::string dialect;  // [RS274NGC]DIALECT, for the preview's line classes
};

int count_lines(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw hal::Error(fmt::format("{}: cannot open the program", path));
    int lines = 0;
    std::string text;
    while (std::getline(in, text)) ++lines;
    return lines;
}

// Another run holding this machine's settings file or tool table would refuse this one only
// after HAL has loaded (the interp component takes the locks when it loads, exit 1). Asked
// here first, the refusal is a configuration error (exit 2) before anything loads or moves;
// the component's own lock stays the guard against a run that starts in between.
void refuse_state_files_in_use(const machine_program::StateFiles& files) {
    for (const std::string* path : {&files.settings, &files.tool_table}) {
        if (path->empty()) continue;
        try {
            const interp::SettingsFileLock probe(*path);
        } catch (const std::runtime_error& e) {
            throw hal::Error(e.what());
        }
    }
}

Config load_config(const RunOptions& o) {
    const hal::IniFile ini = hal::IniFile::load(o.ini);
    Config c;
    const fs::path folder = fs::path(o.ini).parent_path();
    for (const std::string& f : ini.all("HAL", "HALFILE"))
        c.hal_files.push_back(fs::path(f).is_absolute() ? f : (folder / f).string());
    if (c.hal_files.empty())
        throw hal::Error(fmt::format("{}: [HAL]HALFILE is missing: no HAL file to load", o.ini));
    const auto period_ns = ini.get_number("EMCMOT", "SERVO_PERIOD");
    if (!period_ns || !(*period_ns > 0))
        throw hal::Error(fmt::format("{}: [EMCMOT]SERVO_PERIOD (ns, > 0) is missing", o.ini));
    c.period_s = *period_ns * 1e-9;
    for (char ch : ini.get("TRAJ", "COORDINATES").value_or("XYZ")) {
        const char l = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
        if (std::isalpha(static_cast<unsigned char>(l)) &&
            c.axis_letters.find(l) == std::string::npos)
            c.axis_letters += l;
    }
    c.program_lines = count_lines(o.program);
    // The components read [RS274NGC] and the state files again (ini=$(INI_FILE_NAME)); a bad
    // value or settings line is reported here first, as its file:line, before anything loads.
    const machine_program::Options options = machine_program::read_ini(ini, o.settings_dir);
    refuse_state_files_in_use(options.state);
    c.dialect = options.dialect.empty() ? "ncstudio" : options.dialect;
    return c;
}

// The motion pins the loop watches. Axis and joint pins are found by name, so a config with
// any coordinates and joint count works.
struct MachinePins {
    Probe in_position, fault, enable, line, vel;
    std::string letters;  // axes that have axis.L.pos-cmd
    std::vector<Probe> axis_cmd, ferror, ferror_limit, ferrored, amp_fault, joint_fb;
    // interp.done when the config loads the interp component: motion in position is the end
    // only once the interpreter has sent everything (it also stops at queue-busting reads).
    std::optional<Probe> interp_done;
    // motion.program-paused (M00, M01 with the optional-stop switch, single block); read live.
    std::optional<Probe> paused;
    std::vector<std::optional<Probe>> axis_home_shift;  // axis.L.home-shift, where motion has it
};

MachinePins find_pins(hal::Runtime& rt, const std::string& ini, const std::string& letters) {
    if (!try_probe(rt, "motion.in-position"))
        throw hal::Error(fmt::format(
            "{}: the HAL files do not load the motion component (no pin motion.in-position)", ini));
    MachinePins p{Probe(rt, "motion.in-position"),
                  Probe(rt, "motion.fault"),
                  Probe(rt, "motion.enable"),
                  Probe(rt, "motion.program-line"),
                  Probe(rt, "motion.current-vel"),
                  {},
                  {},
                  {},
                  {},
                  {},
                  {},
                  {},
                  try_probe(rt, "interp.done"),
                  try_probe(rt, "motion.program-paused"),
                  {}};
    for (char l : letters) {
        if (auto probe = try_probe(rt, fmt::format("axis.{}.pos-cmd", l))) {
            p.letters += l;
            p.axis_cmd.push_back(*probe);
            p.axis_home_shift.push_back(try_probe(rt, fmt::format("axis.{}.home-shift", l)));
        }
    }
    for (int j = 0;; ++j) {
        auto ferror = try_probe(rt, fmt::format("joint.{}.f-error", j));
        if (!ferror) break;
        p.ferror.push_back(*ferror);
        p.ferror_limit.emplace_back(rt, fmt::format("joint.{}.f-error-lim", j));
        p.ferrored.emplace_back(rt, fmt::format("joint.{}.f-errored", j));
        p.amp_fault.emplace_back(rt, fmt::format("joint.{}.amp-fault-in", j));
        p.joint_fb.emplace_back(rt, fmt::format("joint.{}.motor-pos-fb", j));
    }
    return p;
}

struct Sample {
    double t_s = 0;
    int line = 0;
    std::vector<double> axis_mm, joint_fb_mm, ferror_mm;
    std::vector<double> motion_frame_mm;  // axis_mm less the M902 shifts: what actually moved
    double vel_mm_s = 0;
    bool in_position = false, fault = false, enabled = false;
    bool program_done = true;  // interp.done (true without the interp component)
};

void read_sample(const MachinePins& p, double t_s, Sample& s) {
    s.t_s = t_s;
    s.line = static_cast<int>(p.line.number());
    s.axis_mm.resize(p.axis_cmd.size());
    s.motion_frame_mm.resize(p.axis_cmd.size());
    for (std::size_t k = 0; k < p.axis_cmd.size(); ++k) {
        s.axis_mm[k] = p.axis_cmd[k].number();
        const auto& shift = p.axis_home_shift[k];
        s.motion_frame_mm[k] = s.axis_mm[k] - (shift ? shift->number() : 0.0);
    }
    s.joint_fb_mm.resize(p.joint_fb.size());
    s.ferror_mm.resize(p.ferror.size());
    for (std::size_t j = 0; j < p.ferror.size(); ++j) {
        s.joint_fb_mm[j] = p.joint_fb[j].number();
        s.ferror_mm[j] = p.ferror[j].number();
    }
    s.vel_mm_s = p.vel.number();
    s.in_position = p.in_position.bit();
    s.fault = p.fault.bit();
    s.enabled = p.enable.bit();
    s.program_done = !p.interp_done || p.interp_done->bit();
}

// Running figures for the summary. Velocities and accelerations are differences of
// consecutive commanded positions, so they need every servo cycle (--sim-clock).
class Stats {
  public:
    Stats(std::string letters, std::size_t joints, bool every_cycle, double period_s)
        : letters_(std::move(letters)),
          every_cycle_(every_cycle),
          period_s_(period_s),
          max_ferror_mm_(joints, 0.0),
          max_vel_(letters_.size(), 0.0),
          max_acc_(letters_.size(), 0.0),
          prev_vel_(letters_.size(), 0.0) {}

    void add(const Sample& s) {
        for (std::size_t j = 0; j < s.ferror_mm.size(); ++j)
            max_ferror_mm_[j] = std::max(max_ferror_mm_[j], std::fabs(s.ferror_mm[j]));
        if (!prev_pos_.empty()) {
            double d2 = 0;
            for (std::size_t k = 0; k < letters_.size(); ++k) {
                const double d = s.motion_frame_mm[k] - prev_pos_[k];
                if (is_linear(letters_[k])) d2 += d * d;
                if (!every_cycle_) continue;
                const double v = d / period_s_;
                max_vel_[k] = std::max(max_vel_[k], std::fabs(v));
                max_acc_[k] = std::max(max_acc_[k], std::fabs(v - prev_vel_[k]) / period_s_);
                prev_vel_[k] = v;
            }
            path_mm_ += std::sqrt(d2);
        }
        prev_pos_ = s.motion_frame_mm;
    }

    void print(std::FILE* out) const {
        std::string linear;
        for (char l : letters_)
            if (is_linear(l)) linear += static_cast<char>(std::toupper(l));
        fmt::print(out, "path length: {:.3f} mm ({})\n", path_mm_, linear);
        std::string ferr;
        for (std::size_t j = 0; j < max_ferror_mm_.size(); ++j)
            ferr += fmt::format("{}j{} {:.4f}", j ? "  " : "", j, max_ferror_mm_[j]);
        fmt::print(out, "max following error (mm): {}\n", ferr.empty() ? "no joints" : ferr);
        if (!every_cycle_) {
            fmt::print(out, "max velocity, acceleration: measured only with --sim-clock\n");
            return;
        }
        fmt::print(out, "max velocity (mm/s): {}\n", per_axis(max_vel_, 3));
        fmt::print(out, "max acceleration (mm/s^2): {}\n", per_axis(max_acc_, 1));
    }

  private:
    static bool is_linear(char l) {
        return std::string_view("xyzuvw").find(l) != std::string_view::npos;
    }
    std::string per_axis(const std::vector<double>& v, int decimals) const {
        std::string s;
        for (std::size_t k = 0; k < letters_.size(); ++k)
            s += fmt::format("{}{} {:.{}f}", k ? "  " : "", letters_[k], v[k], decimals);
        return s;
    }
    std::string letters_;
    bool every_cycle_;
    double period_s_;
    double path_mm_ = 0;
    std::vector<double> max_ferror_mm_, max_vel_, max_acc_, prev_vel_, prev_pos_;
};

// Progress on stdout: a redrawn bar on a terminal, otherwise one plain line per second of
// motion time (deterministic under --sim-clock).
class Progress {
  public:
    Progress(int total_lines, bool tty) : total_lines_(std::max(total_lines, 1)), tty_(tty) {}

    void update(double t_s, int line) {
        const double percent = std::min(100.0, 100.0 * line / total_lines_);
        if (tty_) {
            const auto now = std::chrono::steady_clock::now();
            if (drawn_ && now - last_draw_ < std::chrono::duration<double>(kTtyRedrawS)) return;
            last_draw_ = now;
            drawn_ = true;
            const int filled = static_cast<int>(percent / 100.0 * kBarWidth);
            const std::string eta =
                percent > 0 ? fmt::format("  ETA {:.1f} s", t_s * (100.0 - percent) / percent) : "";
            fmt::print("\r[{}{}] {:3.0f}%  line {}/{}  {:.1f} s{}\x1b[K",
                       std::string(static_cast<std::size_t>(filled), '#'),
                       std::string(static_cast<std::size_t>(kBarWidth - filled), '-'), percent,
                       line, total_lines_, t_s, eta);
            std::fflush(stdout);
            return;
        }
        if (t_s + 1e-9 < next_plain_s_) return;
        next_plain_s_ = std::floor(t_s + 1e-9) + 1.0;
        fmt::print("progress: {:7.1f} s  line {}/{}  {:3.0f}%\n", t_s, line, total_lines_, percent);
    }

    // A finished program leaves the bar at 100 %, whatever line the last redraw showed.
    void finish(double t_s, bool finished) {
        if (!tty_ || !drawn_) return;
        if (finished) {
            drawn_ = false;  // force the redraw
            update(t_s, total_lines_);
        }
        fmt::print("\n");
    }

  private:
    int total_lines_;
    bool tty_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point last_draw_{};
    double next_plain_s_ = 1.0;
};

// An error as motion tells it on motion.messages: the place ("file:line", or "file:line:col"
// when the column is known; empty for a fault that names no line, such as a limit switch) and
// the cause.
struct ProgramError {
    std::string place;
    std::string cause;
};

// The program's M801 messages and warnings, from motion's stream motion.messages (the canonical
// stream's wire form): a warning is printed when it arrives, the n-th message when
// motion.message-count reaches n (the machine has got there), each on a line of its own; on a
// terminal the progress bar is cleared first and redrawn by its next update. The stream's end
// records are motion's errors: the first is the program's error, kept for the summary; motion
// sends one more for each later fault (a limit switch in a drive fault's stop ramp).
class OperatorTexts {
  public:
    OperatorTexts(hal::Runtime& rt, bool tty)
        : count_(try_probe(rt, "motion.message-count")), tty_(tty) {
        try {
            ring_ = rt.segment().at<hal::Ring>(rt.stream_offset("motion.messages"));
        } catch (const hal::Error&) {
            return;  // a motion without messages (or none loaded): nothing to show
        }
        if (ring_->fields != interp::wire::kWireFields) ring_ = nullptr;
        record_.resize(interp::wire::kWireFields);
    }

    // The first error motion sent, if any (poll() first).
    const ProgramError* error() const { return errors_.empty() ? nullptr : &errors_.front(); }
    // Every error motion sent so far, in order.
    const std::vector<ProgramError>& errors() const { return errors_; }
    // False when the config's motion has no motion.messages: no error will come from it.
    bool connected() const { return ring_ != nullptr; }

    // On a terminal: clears the progress bar before a line of text (its next update redraws it).
    void clear_bar() {
        if (!tty_) return;
        fmt::print("\r\x1b[K");
        std::fflush(stdout);
    }

    void poll() {
        if (!ring_) return;
        while (ring_->pop(record_.data())) take();
        const double reached = count_ ? count_->number() : 0;
        while (shown_ < reached && !messages_.empty()) {
            clear_bar();
            fmt::print("{}\n", messages_.front());
            std::fflush(stdout);
            messages_.pop_front();
            ++shown_;
        }
    }

  private:
    void take() {
        interp::wire::Record r;
        for (std::size_t i = 0; i < r.size(); ++i) r[i] = record_[i].u64;
        const interp::wire::Decoder::Item item = decoder_.feed(r);
        if (item == interp::wire::Decoder::Item::End && decoder_.failed()) {
            ProgramError& e = errors_.emplace_back(ProgramError{"", decoder_.error_cause()});
            if (const auto& at = decoder_.error_loc())
                e.place = at->col > 0 ? fmt::format("{}:{}:{}", at->file, at->line, at->col)
                                      : fmt::format("{}:{}", at->file, at->line);
        }
        if (item != interp::wire::Decoder::Item::Command) return;
        const interp::Canon& c = decoder_.command();
        if (const auto* m = std::get_if<interp::canon::Message>(&c.cmd)) {
            messages_.push_back(fmt::format("{}:{}: message: {}", c.loc.file, c.loc.line,
                                            m->text.empty() ? "(cleared)" : m->text));
        } else if (const auto* w = std::get_if<interp::canon::Warning>(&c.cmd)) {
            clear_bar();
            fmt::print(stderr, "{}:{}:{}: warning: {}\n", c.loc.file, c.loc.line, c.loc.col,
                       w->text);
        }
    }

    hal::Ring* ring_ = nullptr;
    std::optional<Probe> count_;
    bool tty_;
    std::vector<hal::Value> record_;
    interp::wire::Decoder decoder_;
    std::deque<std::string> messages_;  // decoded, not yet reached
    double shown_ = 0;
    std::vector<ProgramError> errors_;
};

// The trace: a header row, then one row per sample: t, line, axis commands, joint feedback,
// path velocity.
class Trace {
  public:
    Trace(const std::string& path, const std::string& letters, std::size_t joints)
        : file_(std::fopen(path.c_str(), "w"), &std::fclose) {
        if (!file_)
            throw hal::Error(
                fmt::format("{}: cannot open for writing: {}", path, std::strerror(errno)));
        std::string header = "t,line";
        for (char l : letters) header += fmt::format(",{}", l);
        for (std::size_t j = 0; j < joints; ++j) header += fmt::format(",j{}", j);
        fmt::print(file_.get(), "{},vel\n", header);
    }
    void row(const Sample& s) {
        std::FILE* f = file_.get();
        fmt::print(f, "{:.6f},{}", s.t_s, s.line);
        for (double v : s.axis_mm) fmt::print(f, ",{:.6f}", v);
        for (double v : s.joint_fb_mm) fmt::print(f, ",{:.6f}", v);
        fmt::print(f, ",{:.6f}\n", s.vel_mm_s);
    }

  private:
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
};

enum class Outcome {
    Finished,
    Fault,
    Disabled,
    NeverEnabled,
    Timeout,
    Interrupted,
    PausedUnattended
};

// Why motion faulted, from the joint pins of the faulting cycle.
// The first joint whose drive reports a fault, as text, or "". Read live: a drive whose
// enable drops may clear its fault a cycle later, so this is best read at once.
std::string drive_fault_text(const MachinePins& p) {
    for (std::size_t j = 0; j < p.amp_fault.size(); ++j)
        if (p.amp_fault[j].bit()) return fmt::format("drive fault on joint {} (amp-fault-in)", j);
    return "";
}

// Drive faults and following errors, which motion tells only by pins; "" for any other fault
// (a refused line, a limit switch, a G906 timeout, ...), whose cause motion sends on
// motion.messages (OperatorTexts::error) and prints on stderr.
std::string describe_fault(const MachinePins& p, const Sample& s) {
    if (std::string drive = drive_fault_text(p); !drive.empty()) return drive;
    for (std::size_t j = 0; j < p.ferror.size(); ++j) {
        if (p.ferrored[j].bit())
            return fmt::format("following error on joint {}: {:.4f} mm, over its limit {} mm", j,
                               s.ferror_mm[j], p.ferror_limit[j].number());
    }
    return "";
}

// The instance this process owns, torn down on every path out.
struct Session {
    explicit Session(bool sim_clock)
        : runtime({fmt::format("cnc-run-{}", ::getpid()), hal::kDefaultSegmentBytes, sim_clock}),
          backend(runtime),
          script(backend) {}
    ~Session() {
        std::string out;
        try {
            runtime.execute({"stop"}, out);
        } catch (const hal::Error&) {
        }
        script.terminate_children();
        runtime.shutdown();
    }
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;
    void exec(const std::vector<std::string>& words) {
        std::string out;
        runtime.execute(words, out);
        if (!out.empty()) fmt::print(stderr, "{}", out);
    }
    hal::Runtime runtime;
    hal::LocalBackend backend;
    hal::Script script;
};

// The sim configs arm their e-stop latch with a rising edge on the signal estop-reset, where
// a real machine's operator presses reset (LinuxCNC: iocontrol.0.user-enable-out).
void arm_estop(Session& s) {
    const auto reset = try_probe(s.runtime, "estop-reset");
    if (!reset) return;
    s.exec({"sets", "estop-reset", "TRUE"});
}

// X, Y, Z of a sample (0 for an axis the machine lacks), for the preview.
std::array<double, 3> xyz_of(const MachinePins& p, const Sample& s) {
    std::array<double, 3> xyz{0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        const auto at = p.letters.find("xyz"[k]);
        if (at != std::string::npos) xyz[k] = s.axis_mm[at];
    }
    return xyz;
}

struct LoopResult {
    Outcome outcome = Outcome::Finished;
    std::string fault_text;
    int fault_line = 0;          // the program line when the fault appeared
    bool fault_printed = false;  // its error line is on stderr already (announce_fault)
    std::size_t errors_shown = 0;  // motion's errors on stderr (or told by the fault's line)
    Sample last;
    long samples = 0;
};

// A pause (motion.program-paused) is announced once; motion leaves it on a rising
// motion.resume, which the operator gives with Enter, or --resume-pauses at once.
struct PauseState {
    bool operator_present = false;  // stdin is a terminal
    bool announced = false;
    bool resume_raised = false;
};

// Non-blocking: true once the operator has typed a line on the terminal.
bool operator_pressed_enter() {
    pollfd fd{STDIN_FILENO, POLLIN, 0};
    if (::poll(&fd, 1, 0) != 1 || !(fd.revents & POLLIN)) return false;
    char buffer[256];
    const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
    return n > 0 && std::memchr(buffer, '\n', static_cast<std::size_t>(n)) != nullptr;
}

// A fault's error line. A drive fault or following error names the line running when it came;
// motion's own error names the line it is about (a move refused after the machine started
// names the refused line, not the one running) or, for one without a place (a limit switch),
// the line running.
std::string fault_error(const RunOptions& o, const LoopResult& r,
                        const ProgramError* motion_error) {
    const std::string running = fmt::format("{}:{}", o.program, r.fault_line);
    if (!r.fault_text.empty()) return fmt::format("{}: {}", running, r.fault_text);
    if (motion_error)
        return fmt::format("{}: {}", motion_error->place.empty() ? running : motion_error->place,
                           motion_error->cause);
    return fmt::format("{}: motion fault (the cause is in motion's message on stderr)", running);
}

// A fault's error line on stderr once its cause is known, while the machine is still coming to
// rest: a drive fault or following error at once (from the pins), any other fault when motion's
// end record arrives on motion.messages (motion publishes it within about a millisecond). It is
// the fault's only line on stderr: motion prints on stderr only what no reader took from
// motion.messages, and the run's last line repeats it only if it was not printed here.
void announce_fault(const RunOptions& o, LoopResult& r, OperatorTexts& texts) {
    if (r.outcome != Outcome::Fault || r.fault_printed) return;
    if (r.fault_text.empty() && !texts.error()) return;
    r.fault_printed = true;
    texts.clear_bar();
    fmt::print(stderr, "{}\n", fault_error(o, r, texts.error()));
    std::fflush(stderr);
}

// motion's errors other than the run's own, once each, as they arrive (only before `stop`:
// what motion sends at stop it has printed itself). The first is the run's fault when the run
// ended on motion.fault (its line is announce_fault's); otherwise it is printed once the
// outcome is `settled`, before the outcome's own line. A later one is another fault (a limit
// switch in a drive fault's stop ramp, the e-stop): `PROGRAM:LINE: cause` with the line
// running now when motion names no place.
void show_motion_errors(const RunOptions& o, LoopResult& r, OperatorTexts& texts, bool settled) {
    const std::vector<ProgramError>& errors = texts.errors();
    if (r.errors_shown == 0 && !errors.empty()) {
        if (r.outcome == Outcome::Fault)
            r.errors_shown = 1;
        else if (!settled)
            return;  // may still become the run's fault
    }
    for (; r.errors_shown < errors.size(); ++r.errors_shown) {
        const ProgramError& e = errors[r.errors_shown];
        texts.clear_bar();
        fmt::print(stderr, "{}: {}\n",
                   e.place.empty() ? fmt::format("{}:{}", o.program, r.last.line) : e.place,
                   e.cause);
        std::fflush(stderr);
    }
}

// After a fault, before `stop`: waits (wall time, at most kFaultTextWaitS) for motion's end
// record, so its cause is in the error line (a fault the pins do not explain) and the record
// has been taken from motion.messages when `stop` comes (motion then does not print it again).
// Under --sim-clock the machine may be at rest before motion has published it.
void await_fault_text(const RunOptions& o, LoopResult& r, OperatorTexts& texts) {
    if (!texts.connected()) return;
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(kFaultTextWaitS));
    for (;;) {
        texts.poll();
        announce_fault(o, r, texts);
        if (r.outcome != Outcome::Fault || (r.fault_printed && texts.error())) return;
        if (std::chrono::steady_clock::now() >= deadline) return;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
}

// Steps the clock until the program ends or something stops it. `step` moves time on (one
// servo period, or a poll interval of wall time) and returns the time since start.
LoopResult watch(Session& session, const MachinePins& pins, const RunOptions& o,
                 const std::function<void(Sample&)>& next, Stats& stats, Progress& progress,
                 OperatorTexts& texts, Trace* trace, Preview* preview, const StopRequest& stop) {
    LoopResult r;
    Sample& s = r.last;
    bool ever_enabled = false;
    std::optional<double> abort_at_s;
    PauseState pause{::isatty(STDIN_FILENO) == 1};
    for (;;) {
        next(s);
        ++r.samples;
        if (trace) trace->row(s);
        if (preview) preview->add(xyz_of(pins, s), s.line);
        stats.add(s);
        progress.update(s.t_s, s.line);
        texts.poll();
        announce_fault(o, r, texts);
        show_motion_errors(o, r, texts, false);
        if (abort_at_s) {
            if (s.in_position || s.t_s > *abort_at_s + kAbortGraceS) return r;
            continue;
        }
        if (r.outcome == Outcome::Fault) {
            // motion brings the machine to rest itself (a drive fault ramps the command down; a
            // late planner error runs out what was planned): wait for that, within limits.
            if (s.in_position || !s.enabled || s.t_s >= o.timeout_s) return r;
            if (stop.requested() && !abort_at_s) {
                abort_at_s = s.t_s;
                session.exec({"setp", "motion.abort", "TRUE"});
            }
            continue;
        }
        if (s.fault) {
            r.outcome = Outcome::Fault;
            r.fault_text = describe_fault(pins, s);
            r.fault_line = s.line;
            announce_fault(o, r, texts);
            continue;
        }
        ever_enabled = ever_enabled || s.enabled;
        if (ever_enabled && !s.enabled) {
            r.outcome = Outcome::Disabled;
            r.fault_text = drive_fault_text(pins);  // what tripped the e-stop, if a drive did
            return r;
        }
        if (!ever_enabled && s.t_s >= kEnableGraceS) {
            r.outcome = Outcome::NeverEnabled;
            return r;
        }
        if (pins.paused) {
            if (pins.paused->bit()) {
                if (!pause.announced) {
                    pause.announced = true;
                    if (!o.resume_pauses && !pause.operator_present) {
                        r.outcome = Outcome::PausedUnattended;
                        return r;
                    }
                    fmt::print(stderr, "{}{}:{}: program paused{}\n",
                               ::isatty(STDOUT_FILENO) == 1 ? "\n" : "", o.program, s.line,
                               o.resume_pauses ? "; resuming (--resume-pauses)"
                                               : "; press Enter to resume");
                }
                if (!pause.resume_raised && (o.resume_pauses || operator_pressed_enter())) {
                    session.exec({"setp", "motion.resume", "TRUE"});  // motion wants an edge
                    pause.resume_raised = true;
                }
            } else if (pause.announced) {
                if (pause.resume_raised) session.exec({"setp", "motion.resume", "FALSE"});
                pause = PauseState{pause.operator_present};
            }
        }
        if (s.in_position && s.program_done) return r;
        if (s.t_s >= o.timeout_s) {
            r.outcome = Outcome::Timeout;
            return r;
        }
        if (stop.requested()) {
            r.outcome = Outcome::Interrupted;
            abort_at_s = s.t_s;
            session.exec({"setp", "motion.abort", "TRUE"});
        }
    }
}

// Every servo cycle in real time: a `sampler` instance added last to the servo thread copies
// the watched pins into a stream each cycle, and the loop drains it every few milliseconds.
class CycleStream {
  public:
    // nullptr when the config cannot be sampled this way (no servo thread to join, or more
    // pins than a stream record holds); the caller then polls the pins instead.
    static std::unique_ptr<CycleStream> attach(Session& s, const MachinePins& p, double period_s) {
        std::vector<std::string> names{"motion.program-line"};
        std::string cfg = "s";
        for (char l : p.letters) names.push_back(fmt::format("axis.{}.pos-cmd", l));
        for (std::size_t j = 0; j < p.joint_fb.size(); ++j)
            names.push_back(fmt::format("joint.{}.motor-pos-fb", j));
        for (std::size_t j = 0; j < p.ferror.size(); ++j)
            names.push_back(fmt::format("joint.{}.f-error", j));
        names.push_back("motion.current-vel");
        cfg += std::string(names.size() - 1, 'f');
        for (const char* bit : {"motion.in-position", "motion.fault", "motion.enable"}) {
            names.push_back(bit);
            cfg += 'b';
        }
        // interp.done rides along when there is room (5 axes and 5 joints fill the record);
        // otherwise the loop reads it live (see done_after).
        if (p.interp_done && names.size() < hal::kMaxStreamFields) {
            names.push_back("interp.done");
            cfg += 'b';
        }
        // The M902 shifts too, after interp.done, when they fit (see shift_fields); else they
        // are read live, which may misplace an M902's jump by the loop's lag.
        if (has_all_shifts(p) && names.size() == f_without_done(p) + (p.interp_done ? 1 : 0) &&
            names.size() + p.letters.size() <= hal::kMaxStreamFields) {
            for (char l : p.letters) names.push_back(fmt::format("axis.{}.home-shift", l));
            cfg += std::string(p.letters.size(), 'f');
        }
        const std::string thread = servo_thread(s);
        if (thread.empty() || names.size() > hal::kMaxStreamFields) return nullptr;
        s.exec({"loadrt", "sampler", "names=" + std::string(kName), "cfg=" + cfg,
                fmt::format("depth={}", kDepth)});
        for (std::size_t i = 0; i < names.size(); ++i) {
            const std::string input = fmt::format("{}.pin.{}", kName, i);
            const std::string sig = signal_of(s, names[i]);
            if (sig.empty())
                s.exec({"net", fmt::format("{}-{}", kName, i), names[i], input});
            else
                s.exec({"net", sig, input});
        }
        s.exec({"addf", kName, thread});  // last: samples what this cycle produced
        auto* ring = s.runtime.segment().at<hal::Ring>(s.runtime.stream_offset(kName));
        return std::unique_ptr<CycleStream>(new CycleStream(ring, p, period_s));
    }

    // Waits for the next cycle's record. Throws hal::Error when the thread stops producing.
    void next(Sample& s) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
        while (!ring_->pop(record_.data())) {
            if (std::chrono::steady_clock::now() > deadline)
                throw hal::Error("the servo thread stopped running (no cycle for 2 s)");
            std::this_thread::sleep_for(std::chrono::duration<double>(kPollPeriodS));
        }
        s.t_s = static_cast<double>(++cycles_) * period_s_;
        std::size_t f = 0;
        s.line = record_[f++].s32;
        s.axis_mm.resize(axes_);
        for (double& v : s.axis_mm) v = record_[f++].f;
        s.joint_fb_mm.resize(joints_);
        for (double& v : s.joint_fb_mm) v = record_[f++].f;
        s.ferror_mm.resize(joints_);
        for (double& v : s.ferror_mm) v = record_[f++].f;
        s.vel_mm_s = record_[f++].f;
        s.in_position = record_[f++].b;
        s.fault = record_[f++].b;
        s.enabled = record_[f++].b;
        s.program_done = has_done_ ? record_[f++].b : done_after(cycles_);
        s.motion_frame_mm = s.axis_mm;
        for (std::size_t k = 0; k < axes_; ++k) {
            const auto& live = pins_.axis_home_shift[k];
            s.motion_frame_mm[k] -= has_shifts_ ? record_[f++].f : live ? live->number() : 0.0;
        }
    }

    // Cycles lost because the loop fell more than the stream's depth behind.
    std::uint64_t lost_cycles() const noexcept {
        return ring_->overruns.load(std::memory_order_relaxed);
    }

  private:
    static constexpr const char* kName = "cnc-run-sampler";
    static constexpr int kDepth = 8192;  // cycles: 8 s at 1 kHz of slack for the loop

    CycleStream(hal::Ring* ring, const MachinePins& p, double period_s)
        : ring_(ring),
          period_s_(period_s),
          axes_(p.letters.size()),
          joints_(p.ferror.size()),
          has_done_(p.interp_done.has_value() && ring->fields > f_without_done(p)),
          has_shifts_(ring->fields == f_without_done(p) + (has_done_ ? 1 : 0) + axes_ &&
                      axes_ > 0 && (has_done_ || !p.interp_done)),
          pins_(p),
          record_(ring->fields) {}

    // interp.done read live for a record that does not carry it: true only for cycles sampled
    // after the loop first saw it TRUE (a stop at a queue-busting read just before the end
    // must not pass for the end). May end a run a few cycles late, never early.
    bool done_after(long cycle) {
        if (!pins_.interp_done) return true;
        if (done_from_cycle_ < 0 && pins_.interp_done->bit())
            done_from_cycle_ = cycles_ + static_cast<long>(ring_->used());
        return done_from_cycle_ >= 0 && cycle > done_from_cycle_;
    }

    // Fields of a record without interp.done: line, axes, joint feedback, f-errors, velocity
    // and the three motion bits.
    static std::size_t f_without_done(const MachinePins& p) {
        return 1 + p.letters.size() + 2 * p.ferror.size() + 1 + 3;
    }

    static bool has_all_shifts(const MachinePins& p) {
        return std::all_of(p.axis_home_shift.begin(), p.axis_home_shift.end(),
                           [](const auto& probe) { return probe.has_value(); });
    }

    // The thread motion-controller runs in: servo-thread by LinuxCNC's convention, or the
    // only thread there is.
    static std::string servo_thread(Session& s) {
        const std::vector<std::string> threads = s.runtime.names("thread");
        if (std::find(threads.begin(), threads.end(), "servo-thread") != threads.end())
            return "servo-thread";
        return threads.size() == 1 ? threads.front() : "";
    }

    // The signal a pin is on, or "" (`show pin` is the runtime's public view of the wiring).
    static std::string signal_of(Session& s, const std::string& pin) {
        std::string out;
        s.runtime.execute({"show", "pin", pin}, out);
        std::istringstream lines(out);
        std::string line;
        while (std::getline(lines, line)) {
            std::istringstream words(line);
            std::vector<std::string> w{std::istream_iterator<std::string>(words), {}};
            if (w.size() >= 7 && w[4] == pin) return w[6];
        }
        return "";
    }

    hal::Ring* ring_;
    double period_s_;
    std::size_t axes_, joints_;
    bool has_done_;
    bool has_shifts_;  // axis.L.home-shift in the record
    // Outlives the stream (both belong to one run); interp.done and the M902 shifts are read
    // live from it when the record does not carry them.
    const MachinePins& pins_;
    long done_from_cycle_ = -1;
    std::vector<hal::Value> record_;
    long cycles_ = 0;
};

// How the loop gets its samples: under --sim-clock it advances the clock one servo period and
// reads the pins; in real time it drains the cycle stream, or polls the pins every few
// milliseconds when the config cannot be sampled per cycle.
std::function<void(Sample&)> make_source(Session& session, const MachinePins& pins,
                                         const RunOptions& o, double period_s,
                                         CycleStream* stream) {
    if (o.sim_clock) {
        const std::string period = fmt::format("{:.9f}", period_s);
        return [&session, &pins, period, period_s, cycles = 0L](Sample& s) mutable {
            std::string out;
            session.runtime.execute({"advance", period}, out);
            read_sample(pins, static_cast<double>(++cycles) * period_s, s);
        };
    }
    if (stream) return [stream](Sample& s) { stream->next(s); };
    const auto start = std::chrono::steady_clock::now();
    return [&pins, start, next = start](Sample& s) mutable {
        next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(kPollPeriodS));
        std::this_thread::sleep_until(next);
        read_sample(pins,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                    s);
    };
}

// The error line for an outcome other than Finished: `PROGRAM:LINE: what`.
std::string outcome_error(const RunOptions& o, const LoopResult& r,
                          const ProgramError* motion_error) {
    const std::string where = fmt::format("{}:{}", o.program, r.last.line);
    switch (r.outcome) {
        case Outcome::Finished:
            return "";
        case Outcome::Fault:
            return fault_error(o, r, motion_error);
        case Outcome::Disabled:
            return fmt::format(
                "{}: the machine was disabled during the program (e-stop: motion.enable went "
                "FALSE){}",
                where, r.fault_text.empty() ? "" : "; " + r.fault_text);
        case Outcome::NeverEnabled:
            return fmt::format(
                "{}: the machine was never enabled (motion.enable stayed FALSE for {} s)", where,
                kEnableGraceS);
        case Outcome::Timeout:
            return fmt::format("{}: not finished after {} s of motion (--timeout)", where,
                               o.timeout_s);
        case Outcome::Interrupted:
            return fmt::format("{}: stopped on request (Ctrl-C or SIGTERM)", where);
        case Outcome::PausedUnattended:
            return fmt::format(
                "{}: the program paused (M00, M01 or single block) and nothing can resume it: "
                "standard input is not a terminal (run with --resume-pauses to go on at once)",
                where);
    }
    return "";
}

void print_summary(const RunOptions& o, const Config& c, const MachinePins& pins,
                   const LoopResult& r, const Stats& stats, const std::string& error) {
    fmt::print("program: {} ({} lines) on {}\n", o.program, c.program_lines, o.ini);
    fmt::print("clock: {}, servo period {:.3f} ms\n", o.sim_clock ? "simulated" : "real time",
               c.period_s * 1e3);
    fmt::print("result: {}\n", r.outcome == Outcome::Finished      ? "finished"
                               : r.outcome == Outcome::Interrupted ? "stopped on request"
                                                                   : "error");
    fmt::print("motion time: {:.3f} s\n", r.last.t_s);
    stats.print(stdout);
    std::string pos;
    for (std::size_t k = 0; k < pins.letters.size(); ++k)
        pos += fmt::format("{}{} {:.4f}", k ? "  " : "", pins.letters[k], r.last.axis_mm[k]);
    fmt::print("final position (mm): {}\n", pos);
    fmt::print("errors: {}\n", error.empty() ? "none" : error);
}

int run_session(const RunOptions& o, const Config& c, Session& session, const StopRequest& stop) {
    session.script.load_ini(o.ini);
    for (const std::string& f : c.hal_files)
        if (!session.script.run_file(f)) return 1;  // run_file printed file:line: cause
    const MachinePins pins = find_pins(session.runtime, o.ini, c.axis_letters);
    std::unique_ptr<Trace> trace;
    if (!o.trace_path.empty())
        trace = std::make_unique<Trace>(o.trace_path, pins.letters, pins.ferror.size());
    std::unique_ptr<Preview> preview;
    if (!o.preview_path.empty()) {
        try {
            preview = std::make_unique<Preview>(classify_lines(o.program, c.dialect));
        } catch (const interp::Error& e) {
            fmt::print(stderr, "{}\n", e.what());
            return 1;
        }
    }
    // Real time: every cycle through a sampler stream (needs the sampler before start).
    std::unique_ptr<CycleStream> stream;
    if (!o.sim_clock) stream = CycleStream::attach(session, pins, c.period_s);
    // Armed before start, so the latch sees the reset in the first cycle in real time as well.
    arm_estop(session);
    try {
        session.exec({"start"});  // motion plans the program here: a bad one fails now
    } catch (const hal::Error& e) {
        fmt::print(stderr, "{}\n", e.what());
        return 1;
    }

    Stats stats(pins.letters, pins.ferror.size(), o.sim_clock || stream, c.period_s);
    Progress progress(c.program_lines, ::isatty(STDOUT_FILENO) == 1);
    OperatorTexts texts(session.runtime, ::isatty(STDOUT_FILENO) == 1);
    LoopResult r = watch(session, pins, o, make_source(session, pins, o, c.period_s, stream.get()),
                         stats, progress, texts, trace.get(), preview.get(), stop);
    await_fault_text(o, r, texts);
    show_motion_errors(o, r, texts, true);
    progress.finish(r.last.t_s, r.outcome == Outcome::Finished);
    // motion prints on stderr here the errors nobody took from motion.messages, and sends the
    // faults its threads had not sent yet.
    session.exec({"stop"});
    texts.poll();
    if (stream && stream->lost_cycles() > 0)
        fmt::print(stderr, "warning: {} servo cycles were not sampled (this process fell behind)\n",
                   stream->lost_cycles());
    const std::string error = outcome_error(o, r, texts.error());
    print_summary(o, c, pins, r, stats, error);
    if (preview) {
        try {
            preview->write(o.preview_path, PreviewCaption{o.program, o.ini, r.last.t_s});
        } catch (const std::runtime_error& e) {
            fmt::print(stderr, "{}\n", e.what());
            return 1;
        }
        fmt::print("preview: {}\n", o.preview_path);
    }
    if (error.empty()) return 0;
    if (!r.fault_printed) fmt::print(stderr, "{}\n", error);
    return r.outcome == Outcome::Interrupted ? 130 : 1;
}

}  // namespace

CLI::App* add_run_command(CLI::App& app, RunOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "run", "run a G-code program on a machine config: progress, then a summary");
    cmd->add_option("INI", o.ini, "machine config (LinuxCNC-style INI with [HAL]HALFILE)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("PROGRAM", o.program, "G-code program")->required()->check(CLI::ExistingFile);
    cmd->add_flag("--sim-clock", o.sim_clock,
                  "simulated clock: as fast as the CPU allows, every servo cycle seen, "
                  "identical output on every run");
    cmd->add_option("--trace", o.trace_path,
                    "CSV of t,line,axes,joints,vel, one row per servo cycle");
    cmd->add_option("--preview", o.preview_path,
                    "PNG or SVG picture of the path followed (top, front, side and isometric "
                    "views; feeds and rapids)")
        ->check(CLI::Validator(preview_path_error, "FILE.png|FILE.svg"));
    cmd->add_option(
        "--settings-dir", o.settings_dir,
        "keep the interpreter's settings file and tool table ([RS274NGC]PARAMETER_FILE, "
        "[EMCIO]TOOL_TABLE) in this folder instead of the INI's; the INI's files are "
        "read while the folder has none");
    cmd->add_flag("--resume-pauses", o.resume_pauses,
                  "go on at once after M00, M01 or a single-block stop (otherwise Enter on a "
                  "terminal resumes; without a terminal a pause is an error)");
    cmd->add_option("--timeout", o.timeout_s, "give up after this much motion time, s")
        ->check(CLI::PositiveNumber);
    return cmd;
}

namespace {

// --settings-dir made absolute (the components may resolve it from another folder) and created.
std::string prepare_settings_dir(const std::string& dir) {
    if (dir.empty()) return dir;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw hal::Error(fmt::format("--settings-dir {}: {}", dir, ec.message()));
    return fs::absolute(dir).string();
}

}  // namespace

int run_program(const RunOptions& given) {
    RunOptions o = given;
    Config c;
    try {
        o.settings_dir = prepare_settings_dir(o.settings_dir);
        c = load_config(o);
    } catch (const hal::Error& e) {
        fmt::print(stderr, "{}\n", e.what());
        return 2;
    }
    // The config's motion and interp loadrt lines read these (see halfiles/motion_xyz.hal,
    // halfiles/interp.hal); INI_FILE_NAME is LinuxCNC's name for the machine's INI.
    ::setenv("CNC_PROGRAM", o.program.c_str(), 1);
    ::setenv("INI_FILE_NAME", fs::absolute(o.ini).c_str(), 1);
    ::setenv("CNC_SIM_LOCKSTEP", o.sim_clock ? "1" : "0", 1);
    ::setenv("CNC_SETTINGS_DIR", o.settings_dir.c_str(), 1);  // "": the INI's folder
    StopRequest stop;  // before the runtime: its threads inherit the signal mask
    try {
        Session session(o.sim_clock);
        ::setenv("HAL_INSTANCE", session.runtime.paths().instance.c_str(), 1);  // loadusr children
        stop.set_segment_on_quit(session.runtime.paths().shm_name);
        return run_session(o, c, session, stop);
    } catch (const hal::Error& e) {
        fmt::print(stderr, "{}\n", e.what());
        return 1;
    }
}

}  // namespace cncrun
