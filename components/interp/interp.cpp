// interp: runs a G-code program through the interpreter library in a non-realtime thread and
// writes the canonical commands into a HAL stream (interp/canon_wire.hpp records), which the
// motion component reads (`loadrt motion canon=interp.canon`). Queue-busting reads
// (#CURMACHPOS, #CURWORKPOS, G906) wait until motion has followed everything sent and stands
// in position (motion.canon-sync, wired to interp.motion-sync), then read the machine's
// position from interp.machine-pos-L. The work offsets, persistent parameters and tool table
// come from the files the INI names and go back into them as a block changes them
// (machine_state.hpp). See docs/components/interp.md.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <string>

#include "../machine_program_ini.hpp"
#include "hal/component.hpp"
#include "interp/canon_wire.hpp"
#include "program_runner.hpp"

namespace {

constexpr long kDefaultDepth = 1024;
constexpr long kMaxDio = 64;  // NcStudio's ports 0..63, as motion's num_dio

class Interp : public hal::Instance, public interpcomp::MachineLink {
  public:
    // The default instance publishes fixed names (interp.program-line, stream interp.canon);
    // one given a name with names=a prefixes them with it (a.program-line, a.canon).
    std::string pin(std::string_view n) const {
        return default_named() ? "=interp." + std::string(n) : std::string(n);
    }

    Interp()
        : stream_(this, stream_name(), interp::wire::kStreamLayout, stream_depth()),
          runner_(runner_config(), *this) {}

    void start() override {
        if (runner_.start_and_wait_ready()) throw hal::Error(runner_.error());
        on_progress();
    }

    void stop() override {
        runner_.stop();
        report_error();
    }

    ~Interp() override {
        runner_.stop();
        report_error();
    }

    // MachineLink, called on the runner's thread.
    bool push(const interp::wire::Record& r) noexcept override {
        hal::Value v[interp::wire::kWireFields];
        for (std::size_t i = 0; i < r.size(); ++i) v[i].u64 = r[i];
        return stream_.push(v);
    }
    std::uint32_t barriers_reached() const noexcept override { return motion_sync_.get(); }
    double machine_pos_mm(int axis) const noexcept override { return machine_pos_[axis]->get(); }
    std::uint64_t input_bits() const noexcept override { return bits(digital_in_); }
    std::uint64_t output_bits() const noexcept override { return bits(digital_out_); }
    double spindle_rpm() const noexcept override { return spindle_speed_in_.get(); }
    bool probe_tripped() const noexcept override { return probe_tripped_.get(); }
    // interp.probe-pos-L unconnected (NaN): the machine position stands in.
    double probe_pos_mm(int axis) const noexcept override {
        const double trip = probe_pos_[static_cast<std::size_t>(axis)]->get();
        return std::isnan(trip) ? machine_pos_mm(axis) : trip;
    }
    bool abort_requested() const noexcept override { return abort_.get(); }
    void on_progress() noexcept override {
        program_line_ = runner_.line();
        running_ = runner_.running();
        waiting_ = runner_.waiting();
        done_ = runner_.done();
        error_ = runner_.failed();
    }

  private:
    bool default_named() const { return name() == fmt::format("interp.{}", index()); }

    static std::uint64_t bits(const hal::Array<hal::In<bool>>& pins) noexcept {
        std::uint64_t b = 0;
        for (std::size_t n = 0; n < pins.size(); ++n)
            if (pins[n].get()) b |= std::uint64_t{1} << n;
        return b;
    }

    std::size_t read_num_dio() const {
        const long n = arg_int("num_dio", 4);
        if (n < 1 || n > kMaxDio)
            throw hal::Error(fmt::format("num_dio={}: must be 1 to {}", n, kMaxDio));
        return static_cast<std::size_t>(n);
    }

    // interp.machine-pos-x … -c: the interpreter's machine axes X Y Z A B C.
    std::array<std::unique_ptr<hal::In<double>>, interp::kMachineAxes> make_machine_pos() {
        std::array<std::unique_ptr<hal::In<double>>, interp::kMachineAxes> pins;
        for (int a = 0; a < interp::kMachineAxes; ++a)
            pins[a] = std::make_unique<hal::In<double>>(
                this, pin(fmt::format("machine-pos-{}", "xyzabc"[a])));
        return pins;
    }

    std::array<std::unique_ptr<hal::In<double>>, 3> make_probe_pos() {
        std::array<std::unique_ptr<hal::In<double>>, 3> pins;
        for (int a = 0; a < 3; ++a)
            pins[a] =
                std::make_unique<hal::In<double>>(this, pin(fmt::format("probe-pos-{}", "xyz"[a])),
                                                  std::numeric_limits<double>::quiet_NaN());
        return pins;
    }

    std::string stream_name() const {
        if (auto s = arg("stream")) return *s;
        return default_named() ? "interp.canon" : fmt::format("{}.canon", name());
    }

    std::uint32_t stream_depth() const {
        const long n = arg_int("depth", kDefaultDepth);
        if (n < 2 || n > (1L << 20))
            throw hal::Error(fmt::format("depth={}: must be 2 to {} records", n, 1L << 20));
        return static_cast<std::uint32_t>(n);
    }

    interpcomp::RunnerConfig runner_config() const {
        interpcomp::RunnerConfig cfg;
        cfg.program_path = arg("program").value_or("");
        if (cfg.program_path.empty())
            throw hal::Error("program= is required: the G-code file to run");
        if (!std::ifstream(cfg.program_path))
            throw hal::Error(fmt::format("program={}: cannot open the file", cfg.program_path));
        cfg.options =
            machine_program::options_from_args(arg("ini"), arg("dialect"), arg("settings_dir"));
        cfg.standalone = arg_int("standalone", 0) != 0;
        return cfg;
    }

    // An error met after `start` reaches the consumer in the stream's end record, and motion
    // reports it; it is printed here only when nobody can have read it.
    void report_error() {
        if (reported_ || !runner_.failed()) return;
        if (runner_.end_sent() && !arg_int("standalone", 0)) return;
        reported_ = true;
        fmt::print(stderr, "{}: {}\n", name(), runner_.error());
    }

    hal::Out<std::int32_t> program_line_{this, pin("program-line")};
    hal::Out<bool> running_{this, pin("running")};
    hal::Out<bool> waiting_{this, pin("waiting")};
    hal::Out<bool> done_{this, pin("done")};
    hal::Out<bool> error_{this, pin("error")};
    hal::In<bool> abort_{this, pin("abort")};
    hal::In<std::uint32_t> motion_sync_{this, pin("motion-sync")};
    std::array<std::unique_ptr<hal::In<double>>, interp::kMachineAxes> machine_pos_ =
        make_machine_pos();
    // Live machine state for #IMPORTMAP / #OUTPORTMAP / #SSINPORTn / #SSSPINDLEREV and G904
    // (net from motion.digital-in-NN, motion.digital-out-NN, the spindle's speed feedback and
    // motion.probe-tripped).
    std::size_t num_dio_ = read_num_dio();
    hal::Array<hal::In<bool>> digital_in_{this, pin("digital-in-{:02}"), num_dio_};
    hal::Array<hal::In<bool>> digital_out_{this, pin("digital-out-{:02}"), num_dio_};
    hal::In<double> spindle_speed_in_{this, pin("spindle-speed-in")};
    hal::In<bool> probe_tripped_{this, pin("probe-tripped")};
    // interp.probe-pos-x/y/z: where the G904's inputs came (net from motion.probe-pos-L).
    std::array<std::unique_ptr<hal::In<double>>, 3> probe_pos_ = make_probe_pos();
    hal::Stream stream_;
    interpcomp::ProgramRunner runner_;
    bool reported_ = false;
};

}  // namespace

HAL_COMPONENT(interp, Interp, "G-code interpreter writing canonical commands into a HAL stream",
              "program", "ini", "dialect", "settings_dir", "stream", "depth", "standalone",
              "num_dio")
