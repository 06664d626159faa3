// motion: the trajectory controller. A non-realtime planner thread (program_feeder.cpp) runs a
// G-code program through the interpreter and the look-ahead planner; the realtime function
// `motion-controller` samples the planned trajectory once per servo period, applies overrides,
// feed hold and abort, and writes LinuxCNC-named axis and joint pins.
//
// Kinematics inside this component are trivial (joint N follows the axis named by the N-th
// letter of coordinates=); the kins_* components exist for other machines, wired externally
// from the axis.L.pos-cmd pins.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hal/component.hpp"
#include "interp/canon_wire.hpp"
#include "interp/dialect.hpp"
#include "motion/kinematics.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "program_feeder.hpp"

namespace {

constexpr char kLowerAxes[] = "xyzabcuvw";
constexpr char kUpperAxes[] = "XYZABCUVW";
constexpr double kMaxOverride = 1.2;

struct AxisPins {
    int axis;  // index into motion::AxisArray
    std::unique_ptr<hal::Out<double>> pos_cmd;
    std::unique_ptr<hal::Param<double>> max_velocity;
    std::unique_ptr<hal::Param<double>> max_acceleration;
    std::unique_ptr<hal::Param<double>> max_jerk;
};

std::string upper(std::string s) {
    for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

double clamp_override(double v) noexcept {
    if (!(v > 0)) return 0;  // also NaN
    return std::min(v, kMaxOverride);
}

class Motion : public hal::Instance {
  public:
    // `loadrt motion` publishes LinuxCNC's fixed names (axis.x.pos-cmd, joint.0.motor-pos-cmd,
    // motion.enable), so LinuxCNC users' HAL files port; an instance given a name with names=
    // prefixes its pins with it instead (a.axis.x.pos-cmd), so several can coexist.
    std::string pin(std::string_view n) const {
        return name() == fmt::format("motion.{}", index()) ? "=" + std::string(n) : std::string(n);
    }

    Motion()
        : coordinates_(read_coordinates()),
          kins_(coordinates_),
          joint_count_(kins_.joint_count()),
          motor_pos_cmd_(this, pin("joint.{}.motor-pos-cmd"), joint_count_),
          motor_pos_fb_(this, pin("joint.{}.motor-pos-fb"), joint_count_),
          f_error_(this, pin("joint.{}.f-error"), joint_count_),
          amp_enable_out_(this, pin("joint.{}.amp-enable-out"), joint_count_),
          ring_(ring_capacity()) {
        check_num_joints();
        program_path_ = arg("program").value_or("");
        if (!program_path_.empty() && !std::ifstream(program_path_))
            throw hal::Error(fmt::format("program={}: cannot open the file", program_path_));
        if (const auto canon = arg("canon")) {
            if (!program_path_.empty())
                throw hal::Error("give either program= or canon=, not both");
            canon_.emplace(hal::Stream::attach(this, *canon, interp::wire::kStreamLayout));
        }
        dialect_ = arg("dialect").value_or("");
        if (!dialect_.empty() && !interp::find_dialect(dialect_))
            throw hal::Error(fmt::format("dialect={}: unknown dialect", dialect_));
        const long period_ns = arg_int("servo_period_nsec", 1000000);
        if (period_ns <= 0) throw hal::Error("servo_period_nsec must be > 0");
        servo_period_s_ = static_cast<double>(period_ns) * 1e-9;
        lockstep_ = arg_int("sim_lockstep", 0) != 0;
        make_axis_pins();
        joint_cmd_mm_.assign(joint_count_, 0.0);
        shared_function<&Motion::update>("=motion-controller");
    }

    void start() override {
        if (sampler_) {  // a restart after stop: planning continues where it paused
            if (feeder_) feeder_->start_and_wait_ready();
            return;
        }
        motion::PlannerConfig plan = planner_config();
        try {
            motion::validate(plan);
        } catch (const std::invalid_argument& e) {
            throw hal::Error(fmt::format("{}: {}", name(), e.what()));
        }
        sampler_ = std::make_unique<motion::Sampler>(motion::sampler_config(plan), ring_,
                                                     motion::AxisArray{});
        if (program_path_.empty() && !canon_) return;
        motioncomp::FeederConfig cfg;
        cfg.program_path = program_path_;
        if (canon_) cfg.canon_source = [this](interp::wire::Record& r) { return pop_canon(r); };
        cfg.dialect = dialect_;
        cfg.plan = plan;
        cfg.coordinates = coordinates_;
        for (char c : coordinates_) cfg.axis_present[motion::axis_index(c)] = true;
        cfg.blend_tolerance_mm = blend_tolerance_mm_;
        feeder_ = std::make_unique<motioncomp::ProgramFeeder>(std::move(cfg), ring_);
        const bool failed_early = feeder_->start_and_wait_ready();
        // An error found before the first servo period is a configuration error: say so now,
        // so `start` fails with the program's file:line instead of a half-run program and a
        // fault pin. Nothing consumes the ring yet, so it can be emptied here; a later
        // `start` plans the (perhaps corrected) file again.
        if (failed_early) {
            const std::string message = feeder_->error();
            feeder_.reset();
            sampler_.reset();
            while (ring_.size() > 0) ring_.pop();
            throw hal::Error(message);
        }
    }

    void stop() override {
        if (!feeder_) return;
        feeder_->stop();
        report_late_error();
    }

    ~Motion() override {
        if (!feeder_) return;
        feeder_->stop();
        report_late_error();
    }

    void update(hal::Period p) noexcept {
        if (!sampler_) return;  // start() failed: nothing planned, nothing to command
        const bool enable = enable_;
        if (enable && !enable_seen_) drive_fault_ = false;  // re-enabling clears a drive fault
        enable_seen_ = enable;
        apply_abort(abort_ || drive_fault_);
        const bool enabled = enable && !drive_fault_;

        if (lockstep_ && feeder_ && !abort_seen_) feeder_->wait_for_lead();
        sampler_->set_feed_override(clamp_override(feed_override_));
        sampler_->set_rapid_override(clamp_override(rapid_override_));
        sampler_->set_hold(feed_hold_ || !enabled);
        const motion::MotionSample s = sampler_->advance(p.s);
        const motion::SamplerStatus& st = sampler_->status();

        for (const AxisPins& a : axes_) *a.pos_cmd = s.pos_mm[a.axis];
        kins_.inverse(s.pos_mm, joint_cmd_mm_);
        if (write_joints(enabled) && !drive_fault_) {
            drive_fault_ = true;  // the stop ramp starts next period; amps drop now
            for (std::size_t j = 0; j < joint_count_; ++j) amp_enable_out_[j] = false;
        }
        double v2 = 0;
        for (double v : s.vel_mm_s) v2 += v * v;
        current_vel_ = std::sqrt(v2);
        program_line_ = s.line;
        const bool planning = feeder_ && !feeder_->idle();
        const bool queue_empty = st.done || ring_.size() == 0 || st.aborted;
        const bool in_position = !st.moving && queue_empty && !planning;
        in_position_ = in_position;
        if (feeder_) canon_sync_ = feeder_->acknowledge(in_position);
        fault_ = drive_fault_ || (feeder_ && feeder_->failed());
        if (st.starved) starved_periods_ = ++starved_count_;
        ignored_commands_ = feeder_ ? feeder_->ignored_commands() : 0u;
    }

  private:
    // The feeder thread's read of the canonical stream (canon=).
    bool pop_canon(interp::wire::Record& r) noexcept {
        hal::Value v[interp::wire::kWireFields];
        if (!canon_->pop(v)) return false;
        for (std::size_t i = 0; i < r.size(); ++i) r[i] = v[i].u64;
        return true;
    }

    // Abort on a rising edge: a controlled stop, and the rest of the program is given up.
    void apply_abort(bool request) noexcept {
        if (request && !abort_seen_) {
            sampler_->abort();
            if (feeder_) feeder_->abandon();
        }
        if (!request && abort_seen_) sampler_->clear_abort();
        abort_seen_ = request;
    }

    // Joint commands, following errors and amp enables; true if a drive reports a fault or a
    // following error exceeds its limit while enabled.
    bool write_joints(bool enabled) noexcept {
        bool fault = false;
        for (std::size_t j = 0; j < joint_count_; ++j) {
            motor_pos_cmd_[j] = joint_cmd_mm_[j];
            const double ferror = joint_cmd_mm_[j] - motor_pos_fb_[j].get();
            const double limit = max_ferror_[j].get();
            const bool errored = limit > 0 && std::fabs(ferror) > limit;
            f_error_[j] = ferror;
            f_error_lim_[j] = limit;
            f_errored_[j] = errored;
            amp_enable_out_[j] = enabled;
            // A disabled machine may sit anywhere: only an enabled one trips.
            fault = fault || (enabled && (errored || amp_fault_in_[j].get()));
        }
        return fault;
    }

    // An error met while the program was already running has only the fault pin in realtime;
    // the text is printed here, in the configuration world, once.
    void report_late_error() {
        if (error_reported_ || !feeder_->failed()) return;
        error_reported_ = true;
        fmt::print(stderr, "{}: {}\n", name(), feeder_->error());
    }

    std::string read_coordinates() const {
        std::string c = upper(arg("coordinates").value_or(""));
        if (c.empty()) {
            const long n = arg_int("num_joints", 3);
            if (n < 1 || n > motion::kAxes)
                throw hal::Error(fmt::format("num_joints={}: must be 1 to {}", n, motion::kAxes));
            c.assign(kUpperAxes, static_cast<std::size_t>(n));
        }
        for (char ch : c)
            if (motion::axis_index(ch) < 0)
                throw hal::Error(
                    fmt::format("coordinates={}: '{}' is not an axis letter (XYZABCUVW)", c, ch));
        return c;
    }

    std::size_t ring_capacity() const {
        const long n = arg_int("queue", 4096);
        if (n < 2 || n > (1L << 20))
            throw hal::Error(fmt::format("queue={}: must be 2 to {} records", n, 1L << 20));
        return static_cast<std::size_t>(n);
    }

    void check_num_joints() const {
        const long n = arg_int("num_joints", static_cast<long>(joint_count_));
        if (n != static_cast<long>(joint_count_))
            throw hal::Error(fmt::format(
                "num_joints={} does not match coordinates={} ({} joints, one per letter)", n,
                coordinates_, joint_count_));
    }

    void make_axis_pins() {
        for (int k = 0; k < motion::kAxes; ++k) {
            if (coordinates_.find(kUpperAxes[k]) == std::string::npos) continue;
            const std::string stem = pin(fmt::format("axis.{}", kLowerAxes[k]));
            AxisPins a;
            a.axis = k;
            a.pos_cmd = std::make_unique<hal::Out<double>>(this, stem + ".pos-cmd");
            a.max_velocity =
                std::make_unique<hal::Param<double>>(this, stem + ".max-velocity", 100.0);
            a.max_acceleration =
                std::make_unique<hal::Param<double>>(this, stem + ".max-acceleration", 1000.0);
            a.max_jerk = std::make_unique<hal::Param<double>>(this, stem + ".max-jerk", 0.0);
            axes_.push_back(std::move(a));
        }
    }

    // Limits from the params at start(); axes the machine lacks get the loosest present
    // limits so validate() passes (the feeder refuses moves on them anyway).
    motion::PlannerConfig planner_config() const {
        motion::PlannerConfig plan;
        plan.servo_period_s = servo_period_s_;
        plan.max_rate = kMaxOverride;
        for (const AxisPins& a : axes_) {
            plan.limits.vel_mm_s[a.axis] = a.max_velocity->get();
            plan.limits.acc_mm_s2[a.axis] = a.max_acceleration->get();
            plan.limits.jerk_mm_s3[a.axis] = a.max_jerk->get();
        }
        for (int k = 0; k < motion::kAxes; ++k) {
            if (coordinates_.find(kUpperAxes[k]) != std::string::npos) continue;
            plan.limits.vel_mm_s[k] = 1e9;
            plan.limits.acc_mm_s2[k] = 1e9;
            plan.limits.jerk_mm_s3[k] = 0;
        }
        for (const AxisPins& a : axes_) {
            if (!(a.max_velocity->get() > 0) || !(a.max_acceleration->get() > 0) ||
                !(a.max_jerk->get() >= 0))
                throw hal::Error(fmt::format(
                    "{}: axis.{}: max-velocity and max-acceleration must be > 0, max-jerk >= 0",
                    name(), kLowerAxes[a.axis]));
        }
        if (!(blend_tolerance_mm_.get() >= 0))
            throw hal::Error(fmt::format("{}: motion.blend-tolerance must be >= 0 mm", name()));
        return plan;
    }

    std::string coordinates_;
    motion::TrivialKinematics kins_;
    std::size_t joint_count_;

    hal::Array<hal::Out<double>> motor_pos_cmd_;
    hal::Array<hal::In<double>> motor_pos_fb_;
    hal::Array<hal::Out<double>> f_error_;
    hal::Array<hal::Out<bool>> amp_enable_out_;
    hal::Array<hal::In<bool>> amp_fault_in_{this, pin("joint.{}.amp-fault-in"), joint_count_};
    hal::Array<hal::Out<double>> f_error_lim_{this, pin("joint.{}.f-error-lim"), joint_count_};
    hal::Array<hal::Out<bool>> f_errored_{this, pin("joint.{}.f-errored"), joint_count_};
    hal::Array<hal::Param<double>> max_ferror_{this, pin("joint.{}.max-ferror"), joint_count_};
    std::vector<AxisPins> axes_;

    hal::In<bool> enable_{this, pin("motion.enable")};
    hal::In<bool> feed_hold_{this, pin("motion.feed-hold")};
    hal::In<bool> abort_{this, pin("motion.abort")};
    hal::In<double> feed_override_{this, pin("motion.feed-override"), 1.0};
    hal::In<double> rapid_override_{this, pin("motion.rapid-override"), 1.0};
    hal::Out<double> current_vel_{this, pin("motion.current-vel")};
    hal::Out<std::int32_t> program_line_{this, pin("motion.program-line")};
    hal::Out<bool> in_position_{this, pin("motion.in-position"), true};
    hal::Out<bool> fault_{this, pin("motion.fault")};
    hal::Out<std::uint32_t> ignored_commands_{this, pin("motion.ignored-commands")};
    hal::Out<std::uint32_t> starved_periods_{this, pin("motion.starved-periods")};
    hal::Param<double> blend_tolerance_mm_{this, pin("motion.blend-tolerance"), 0.01};

    motion::SpscRing<motion::PreparedSegment> ring_;
    std::unique_ptr<motion::Sampler> sampler_;
    std::unique_ptr<motioncomp::ProgramFeeder> feeder_;
    std::optional<hal::Stream> canon_;  // canon=: the interp component's stream
    hal::Out<std::uint32_t> canon_sync_{this, pin("motion.canon-sync")};
    std::string program_path_;
    std::string dialect_;
    double servo_period_s_ = 1e-3;
    std::vector<double> joint_cmd_mm_;
    bool abort_seen_ = false;
    bool enable_seen_ = false;
    bool drive_fault_ = false;  // latched until motion.enable rises again
    std::uint32_t starved_count_ = 0;
    bool lockstep_ = false;
    bool error_reported_ = false;  // wait for the planner each period (simulated clock only)
};

}  // namespace

HAL_COMPONENT(motion, Motion, "Trajectory planner and servo-rate motion controller", "num_joints",
              "coordinates", "program", "canon", "dialect", "servo_period_nsec", "queue", "sim_lockstep")
