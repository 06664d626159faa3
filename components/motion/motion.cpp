// motion: the trajectory controller. A non-realtime planner thread (program_feeder.cpp) runs a
// G-code program through the interpreter and the look-ahead planner; the realtime function
// `motion-controller` samples the planned trajectory once per servo period, applies overrides,
// feed hold and abort, and writes LinuxCNC-named axis and joint pins. Machine commands of the
// program (spindle, coolant, tool change, digital outputs and inputs, M00/M01) reach it as
// action records in the same ring, in program order, and are carried out here on the pins
// LinuxCNC's motion and iocontrol publish (spindle.0.*, iocontrol.0.*, motion.digital-*).
//
// Joints are the machine's motors: every period the sampled axis position goes through the
// machine's kinematics (kins_link.hpp: built-in trivial, or the kins_* module named by kins=)
// to joint.N.motor-pos-cmd, and the joint feedback back through forward() to axis.L.pos-fb.
// Following errors, limit switches, joint velocity/acceleration and the joint soft limits are
// per joint. The planner thread refuses a move whose path leaves the axis soft limits, or takes
// a joint past its soft limit (through a kinematics of its own, joint_limits.hpp), before it
// starts; the servo function checks the joint commands again as the last line of defence.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../machine_program_ini.hpp"
#include "hal/component.hpp"
#include "hal/worker.hpp"
#include "interp/canon_wire.hpp"
#include "kins_link.hpp"
#include "motion/kinematics.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "program_feeder.hpp"

namespace {

constexpr char kLowerAxes[] = "xyzabcuvw";
constexpr char kUpperAxes[] = "XYZABCUVW";
constexpr double kMaxOverride = 1.2;
constexpr long kMaxDio = 64;  // NcStudio's M901 H0..H63

// Why motion faulted, kept by the servo function for the text the non-realtime side makes of
// it (on motion.messages as soon as the stream's producer polls; on stderr at stop or unload
// if no reader took it from the stream).
enum class FaultCause : std::uint8_t {
    None,
    EStop,
    PosLimit,
    NegLimit,
    WaitTimeout,
    KinsLost,
    ToolOffsetJump,
    JointSoftLimit,
    FollowingError,
    AmpFault
};
struct FaultReport {
    FaultCause cause = FaultCause::None;
    int joint = 0;
    std::int32_t line = 0;
    motion::Action action;
    double amount = 0;  // ToolOffsetJump: how far the joint would have jumped; JointSoftLimit:
                        // the joint's command; FollowingError: the following error
    double min_mm = 0, max_mm = 0;  // JointSoftLimit: the joint's limits; FollowingError:
                                    // max_mm = joint.N.max-ferror
};

// The e-stop handshake of LinuxCNC's iocontrol: iocontrol.0.emc-enable-in FALSE trips it
// (user-enable-out drops with it); a rising motion.enable asks for a reset (user-enable-out
// TRUE again), and the machine is ready once emc-enable-in is TRUE.
enum class EStop : std::uint8_t { Ready, Tripped, Resetting };

struct AxisPins {
    int axis;  // index into motion::AxisArray
    std::unique_ptr<hal::Out<double>> pos_cmd;
    std::unique_ptr<hal::Out<double>> pos_fb;  // forward kinematics of the joint feedback
    // Machine coordinate minus the planner's frame (M902): a jump of pos-cmd by a change of
    // it is no motion, and readers of pos-cmd (cnc run's figures) subtract it.
    std::unique_ptr<hal::Out<double>> home_shift;
    std::unique_ptr<hal::Param<double>> max_velocity;
    std::unique_ptr<hal::Param<double>> max_acceleration;
    std::unique_ptr<hal::Param<double>> max_jerk;
    std::unique_ptr<hal::Param<double>> min_limit;
    std::unique_ptr<hal::Param<double>> max_limit;
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
        : kins_(link_kinematics()),
          coordinates_(machine_coordinates()),
          joint_count_(kins_.kins().joint_count()),
          motor_pos_cmd_(this, pin("joint.{}.motor-pos-cmd"), joint_count_),
          motor_pos_fb_(this, pin("joint.{}.motor-pos-fb"), joint_count_),
          f_error_(this, pin("joint.{}.f-error"), joint_count_),
          amp_enable_out_(this, pin("joint.{}.amp-enable-out"), joint_count_),
          num_dio_(read_num_dio()),
          digital_out_(this, pin("motion.digital-out-{:02}"), num_dio_),
          digital_in_(this, pin("motion.digital-in-{:02}"), num_dio_),
          ring_(ring_capacity()),
          messages_(this, stream_name("messages"), interp::wire::kStreamLayout, kMessageDepth) {
        check_num_joints();
        program_path_ = arg("program").value_or("");
        if (!program_path_.empty() && !std::ifstream(program_path_))
            throw hal::Error(fmt::format("program={}: cannot open the file", program_path_));
        if (const auto canon = arg("canon")) {
            if (!program_path_.empty())
                throw hal::Error("give either program= or canon=, not both");
            canon_.emplace(hal::Stream::attach(this, *canon, interp::wire::kStreamLayout));
        }
        program_options_ =
            machine_program::options_from_args(arg("ini"), arg("dialect"), arg("settings_dir"));
        const long period_ns = arg_int("servo_period_nsec", 1000000);
        if (period_ns <= 0) throw hal::Error("servo_period_nsec must be > 0");
        servo_period_s_ = static_cast<double>(period_ns) * 1e-9;
        lockstep_ = arg_int("sim_lockstep", 0) != 0;
        make_axis_pins();
        joint_cmd_mm_.assign(joint_count_, 0.0);
        joint_fb_mm_.assign(joint_count_, 0.0);
        joint_vel_mm_s_.assign(joint_count_, 0.0);
        joint_prev_mm_.assign(joint_count_, 0.0);
        joint_excess_.assign(joint_count_, JointExcess{});
        offset_before_mm_.assign(joint_count_, 0.0);
        offset_after_mm_.assign(joint_count_, 0.0);
        pos_lim_seen_.assign(joint_count_, 0);
        lim_prev_cmd_mm_.assign(joint_count_, 0.0);
        neg_lim_seen_.assign(joint_count_, 0);
        shared_function<&Motion::take_commands>("=motion-command-handler");
        shared_function<&Motion::update>("=motion-controller");
    }

    void start() override {
        if (sampler_) {  // a restart after stop: planning continues where it paused
            if (feeder_)
                feeder_->start_and_wait_ready();
            else
                start_fault_poller();
            return;
        }
        motion::PlannerConfig plan = planner_config();
        joints_planned_ = !kins_.kins().linear_map().empty();
        try {
            motion::validate(plan);
        } catch (const std::invalid_argument& e) {
            throw hal::Error(fmt::format("{}: {}", name(), e.what()));
        }
        sampler_ = std::make_unique<motion::Sampler>(motion::sampler_config(plan), ring_,
                                                     motion::AxisArray{});
        if (program_path_.empty() && !canon_) {
            start_fault_poller();
            return;
        }
        motioncomp::FeederConfig cfg;
        cfg.program_path = program_path_;
        if (canon_) cfg.canon_source = [this](interp::wire::Record& r) { return pop_canon(r); };
        cfg.program_options = program_options_;
        cfg.plan = plan;
        cfg.coordinates = coordinates_;
        for (char c : coordinates_) cfg.axis_present[motion::axis_index(c)] = true;
        cfg.blend_tolerance_mm = blend_tolerance_mm_;
        cfg.machine = sink_config();
        cfg.on_text = [this](const interp::Canon& c) { publish_text(c); };
        cfg.on_error = [this](const std::optional<interp::SourceLoc>& where,
                              std::string_view cause) {
            publish_faults();  // a servo fault noted first stopped the program first
            publish_planner_error(where, cause);
        };
        cfg.on_poll = [this] { publish_faults(); };
        feeder_ = std::make_unique<motioncomp::ProgramFeeder>(std::move(cfg), ring_);
        const bool failed_early = feeder_->start_and_wait_ready();
        // An error found before the first servo period is a configuration error: say so now,
        // so `start` fails with the program's file:line instead of a half-run program and a
        // fault pin. Nothing consumes the ring yet, so it can be emptied here; a later
        // `start` plans the (perhaps corrected) file again.
        if (failed_early) {
            const std::string message = feeder_->error();
            feeder_->stop();  // joined while feeder_ still points at it (on_poll reads it)
            feeder_.reset();
            errors_.clear();  // the start's error says it
            sampler_.reset();
            while (ring_.size() > 0) ring_.pop();
            throw hal::Error(message);
        }
    }

    void stop() override {
        if (feeder_) feeder_->stop();
        fault_poller_.pause_and_join();
        report_late_error();
        report_joint_excess();
    }

    ~Motion() override {
        if (feeder_) feeder_->stop();
        fault_poller_.pause_and_join();
        report_late_error();
        report_joint_excess();
    }

    // motion-command-handler (LinuxCNC's name and place: before motion-controller): takes the
    // operator's commands of this period, motion.enable (a rising edge is the reset),
    // motion.resume and the e-stop chain. motion-controller takes them itself in a period this
    // function did not run in, so a thread without it works the same.
    void take_commands(hal::Period) noexcept {
        if (!sampler_) return;
        enable_now_ = enable_;
        const bool enable_rose = enable_now_ && !enable_seen_;
        enable_seen_ = enable_now_;
        const bool resume = resume_;
        resume_rose_ = resume && !resume_seen_;
        resume_seen_ = resume;
        if (enable_rose) clear_latches();
        update_estop();
        commands_taken_ = true;
    }

    void update(hal::Period p) noexcept {
        if (!sampler_) return;  // start() failed: nothing planned, nothing to command
        if (!commands_taken_) take_commands(p);
        commands_taken_ = false;
        const bool enable = enable_now_;
        check_limit_switches(enable);
        const bool faulted = drive_fault_ || limit_fault_ || estop_ == EStop::Tripped ||
                             program_fault_ || kins_lost_;
        apply_stops(abort_, faulted);
        const bool enabled = enable && !faulted && estop_ == EStop::Ready;

        if (lockstep_ && feeder_ && !stop_seen_) feeder_->wait_for_lead();
        sampler_->set_feed_override(clamp_override(feed_override_));
        sampler_->set_rapid_override(clamp_override(rapid_override_));
        sampler_->set_hold(feed_hold_ || !enabled);
        sampler_->set_single_block(single_block_);
        sampler_->set_inputs(read_inputs());
        if (resume_rose_ && sampler_->status().block_paused) sampler_->resume_block();
        const motion::MotionSample s = sampler_->advance(p.s);
        const motion::SamplerStatus& st = sampler_->status();
        action_pos_mm_ = s.pos_mm;  // standing on an action: where the machine stands
        apply_sync_outputs();
        if (enabled) run_pending_action(s.line, p.s);

        // Machine coordinates: the planner's frame plus the shifts M902 has set.
        for (const AxisPins& a : axes_) {
            *a.pos_cmd = s.pos_mm[a.axis] + home_shift_mm_[a.axis];
            *a.home_shift = home_shift_mm_[a.axis];
        }
        check_kinematics();  // after the actions: a tool offset set now applies now
        kins_.kins().inverse(s.pos_mm, joint_cmd_mm_);
        check_joint_limits(enabled, s.line);  // before check_joint_motion moves joint_prev_mm_
        check_joint_motion(p.s, s.line);
        // A joint limit tripped now drops the amps now, as a limit switch does.
        if (write_joints(enabled && !limit_fault_, s.line) && !drive_fault_) {
            drive_fault_ = true;  // the stop ramp starts next period; amps drop now
            for (std::size_t j = 0; j < joint_count_; ++j) amp_enable_out_[j] = false;
        }
        write_axis_feedback(s.pos_mm);
        double v2 = 0;
        for (double v : s.vel_mm_s) v2 += v * v;
        current_vel_ = std::sqrt(v2);
        program_line_ = s.line;
        last_line_ = s.line;
        const bool planning = feeder_ && !feeder_->idle();
        const bool queue_empty = st.done || ring_.size() == 0 || st.aborted;
        const bool in_position = !st.moving && queue_empty && !planning;
        in_position_ = in_position;
        if (feeder_) canon_sync_ = feeder_->acknowledge(in_position);
        program_paused_ = st.block_paused || pausing_;
        fault_ = drive_fault_ || limit_fault_ || estop_ == EStop::Tripped || program_fault_ ||
                 kins_lost_ || (feeder_ && feeder_->failed());
        if (st.starved) starved_periods_ = ++starved_count_;
        ignored_commands_ = feeder_ ? feeder_->ignored_commands() : 0u;
        message_dropped_ = dropped_texts_.load(std::memory_order_relaxed);
    }

  private:
    static constexpr std::uint32_t kMessageDepth = 256;  // records of motion.messages

    // A stream of this instance: motion.NAME, or INSTANCE.NAME for an instance given a name.
    std::string stream_name(std::string_view n) const {
        const std::string p = pin(fmt::format("motion.{}", n));
        return p[0] == '=' ? p.substr(1) : fmt::format("{}.{}", name(), n);
    }

    // motion.messages, in the canonical stream's wire form, for `cnc run` or another reader:
    // M801 messages and warnings as commands, and errors as end records with their place
    // (file, line, column when known) apart from their cause. hal::Stream is SPSC, so one
    // producer at a time, handed over only where a thread join orders the two:
    //  - from start() until stop() joins it, the instance's one non-realtime thread: the feeder
    //    thread (texts as they are planned, a planning error when it is found, and each fault
    //    of the servo function within a millisecond of the period that noted it: the thread
    //    stays after the program is over to poll for them, ProgramFeeder::linger), or, in an
    //    instance without program= and canon=, the fault poller (faults only);
    //  - the configuration world after the join (stop, unload, a start that failed): faults
    //    noted while no thread ran (after stop), and nothing twice.
    // The servo function never writes the stream: it only pushes reports into faults_.
    void publish_text(const interp::Canon& c) {
        const std::size_t files = text_encoder_.files_announced();
        text_records_.clear();
        text_encoder_.command(c, text_records_);
        publish_records(files);
    }

    // An instance without a feeder thread still needs a producer polling faults_ while it runs
    // (a machine driven by jogs or a HAL stream of its own faults as well); started by start(),
    // joined by stop(). Polling, as the servo function may not wake a thread.
    void start_fault_poller() {
        fault_poller_.start_and_wait_ready([this] {
            fault_poller_.mark_ready(false);
            while (!fault_poller_.pause_requested()) {
                try {
                    publish_faults();
                } catch (const std::exception&) {
                    // Out of memory formatting a text: tried again at the next poll.
                }
                std::this_thread::sleep_for(motioncomp::ProgramFeeder::kLingerPoll);
            }
        });
    }

    // Each fault the servo function noted, in order, by the stream's current producer (see
    // above), each as an end record of its own: the first is the one that stopped the program,
    // a later one is another fault (a limit switch in a drive fault's stop ramp, a fault after
    // a reset). A fault at a program line has no place in an instance without a program (a
    // following error while jogging). The report leaves faults_ only once its records are
    // built and pushed (or dropped), so a throw retries it at the next poll.
    void publish_faults() {
        while (faults_.size() > 0) {
            const FaultReport r = faults_.peek(0);
            const std::string cause = fault_cause(r);
            const std::string file = feeder_ ? feeder_->program_file() : program_path_;
            if (names_line(r.cause) && !file.empty()) {
                publish_error(interp::SourceLoc{file, r.line, 0}, cause,
                              fmt::format("{}:{}: {}", file, r.line, cause));
            } else {
                publish_error(std::nullopt, cause, cause);
            }
            faults_.pop();
        }
    }

    // The planner thread's error (or the interp component's, through canon=), on that thread.
    // Its stderr text is the feeder's, "file:line:col: reason".
    void publish_planner_error(const std::optional<interp::SourceLoc>& where,
                               std::string_view cause) {
        publish_error(where, cause.empty() ? "the program failed" : cause, feeder_->error());
    }

    // One error as an end record, remembered with its stderr text `text` and the number of
    // records pushed once it was in: a reader that has popped that many has taken it.
    void publish_error(const std::optional<interp::SourceLoc>& where, std::string_view cause,
                       std::string text) {
        const std::size_t files = text_encoder_.files_announced();
        text_records_.clear();
        if (where)
            text_encoder_.end(*where, cause, text_records_);
        else
            text_encoder_.end(cause, text_records_);
        SentError e{std::move(text), 0};
        errors_.reserve(errors_.size() + 1);  // a throw here leaves nothing pushed
        if (publish_records(files)) e.taken_at = records_pushed_;
        errors_.push_back(std::move(e));
    }

    // A text that does not fit (nobody reads the stream) is dropped whole, so a reader never
    // sees half of one, and counted on motion.message-dropped (motion.message-count still
    // counts the messages reached). A file announced only in the dropped records is announced
    // again by the next text that names it.
    // Returns whether the text went out.
    bool publish_records(std::size_t files_before) {
        if (messages_.depth() - messages_.used() < text_records_.size()) {
            text_encoder_.forget_files_after(files_before);
            dropped_texts_.fetch_add(1, std::memory_order_relaxed);
            return false;
        }
        hal::Value v[interp::wire::kWireFields];
        for (const interp::wire::Record& r : text_records_) {
            for (std::size_t i = 0; i < r.size(); ++i) v[i].u64 = r[i];
            messages_.push(v);
            ++records_pushed_;
        }
        return true;
    }

    // The feeder thread's read of the canonical stream (canon=).
    bool pop_canon(interp::wire::Record& r) noexcept {
        hal::Value v[interp::wire::kWireFields];
        if (!canon_->pop(v)) return false;
        for (std::size_t i = 0; i < r.size(); ++i) r[i] = v[i].u64;
        return true;
    }

    // A rising motion.abort stops along the path within the jerk limit; a fault stops at the
    // acceleration limit. Either gives the rest of the program up and turns the spindle and
    // coolant off; when both requests are gone the sampler accepts records again.
    void apply_stops(bool user_abort, bool fault) noexcept {
        if (fault && !fault_seen_) {
            sampler_->fault_stop();
            give_up();
        }
        if (user_abort && !abort_seen_) {
            sampler_->abort();
            give_up();
        }
        const bool request = user_abort || fault;
        if (!request && stop_seen_) sampler_->clear_abort();
        abort_seen_ = user_abort;
        fault_seen_ = fault;
        stop_seen_ = request;
    }

    void give_up() noexcept {
        if (feeder_) feeder_->abandon();
        spindle_dir_ = 0;
        write_spindle();
        spindle_orient_ = false;
        coolant_flood_ = false;
        coolant_mist_ = false;
        tool_prepare_ = false;
        tool_change_ = false;
        pausing_ = false;
        limits_masked_ = false;  // an abandoned program's M802 P131072 ends with it
        limits_masked_pin_ = false;
        action_started_ = false;
    }

    // A rising motion.enable clears latched faults (the e-stop needs its own reset, below).
    void clear_latches() noexcept {
        drive_fault_ = false;
        limit_fault_ = false;
        if (estop_ == EStop::Tripped) estop_ = EStop::Resetting;
    }

    void update_estop() noexcept {
        const bool ok = emc_enable_in_;
        if (!ok && estop_ == EStop::Ready) {
            estop_ = EStop::Tripped;
            note_fault({FaultCause::EStop, 0, last_line_, {}});
        } else if (ok && estop_ == EStop::Resetting) {
            estop_ = EStop::Ready;
        }
        user_enable_out_ = estop_ != EStop::Tripped;
        if (estop_ == EStop::Tripped)
            for (std::size_t j = 0; j < joint_count_; ++j) amp_enable_out_[j] = false;
    }

    // A limit switch that closes while the machine is enabled trips a fault. One still closed
    // after a reset lets the joint move off it (away from the switch) but trips again as soon
    // as the joint is commanded further into it (LinuxCNC allows only the move away, too).
    // joint_cmd_mm_ still holds last period's commands here: its step is the joint's direction.
    void check_limit_switches(bool enable) noexcept {
        constexpr double kStill_mm = 1e-9;  // per period: rounding, not motion
        for (std::size_t j = 0; j < joint_count_; ++j) {
            const bool pos = pos_lim_sw_in_[j], neg = neg_lim_sw_in_[j];
            const double step_mm = joint_cmd_mm_[j] - lim_prev_cmd_mm_[j];
            lim_prev_cmd_mm_[j] = joint_cmd_mm_[j];
            const bool trip_pos = pos && (!pos_lim_seen_[j] || step_mm > kStill_mm);
            const bool trip_neg = neg && (!neg_lim_seen_[j] || step_mm < -kStill_mm);
            pos_lim_seen_[j] = pos;
            neg_lim_seen_[j] = neg;
            // Masked (M802 P131072): no trip; a switch still closed when they are obeyed again
            // lets the joint move off it only, like one closed before enabling.
            if (limits_masked_) continue;
            if (!enable || limit_fault_ || !(trip_pos || trip_neg)) continue;
            limit_fault_ = true;
            const FaultCause cause = trip_pos ? FaultCause::PosLimit : FaultCause::NegLimit;
            note_fault({cause, static_cast<int>(j), last_line_, {}});
            for (std::size_t k = 0; k < joint_count_; ++k) amp_enable_out_[k] = false;
        }
    }

    // Every fault is reported: the callers note one when a latch sets (a drive or
    // following-error trip, a limit, the e-stop, a program fault, a lost kinematics), so at
    // most one of each kind until motion.enable rises again. faults_ is preallocated; one that
    // finds it full (more than kFaultReports faults before the producer's next poll) is only
    // counted, and said at stop.
    void note_fault(const FaultReport& r) noexcept {
        if (!faults_.try_push(r)) faults_lost_.fetch_add(1, std::memory_order_relaxed);
    }

    // ---- machine commands (action records) ----

    void write_spindle() noexcept {
        const double rpm = spindle_dir_ * spindle_rpm_;
        spindle_speed_out_ = rpm;
        spindle_speed_out_abs_ = std::fabs(rpm);
        spindle_on_ = spindle_dir_ != 0;
        spindle_forward_ = spindle_dir_ > 0;
        spindle_reverse_ = spindle_dir_ < 0;
    }

    // Carries out the action the sampler stands on, over as many periods as it takes; tells
    // the sampler when it is complete. A handshake input is read from the period after its
    // output was set, so a drive or a loopback has one period to answer.
    void run_pending_action(std::int32_t line, double dt) noexcept {
        const motion::Action* a = sampler_->pending_action();
        if (!a) {
            action_started_ = false;
            return;
        }
        const bool first = !action_started_;
        if (first) {
            action_started_ = true;
            action_stage_ = 0;
            action_waited_s_ = 0;
        } else {
            action_waited_s_ += dt;
        }
        if (step_action(*a, first, line)) {
            action_started_ = false;
            sampler_->action_done();
        }
    }

    bool step_action(const motion::Action& a, bool first, std::int32_t line) noexcept {
        switch (a.kind) {
            case motion::ActionKind::SpindleSpeed:
                spindle_rpm_ = a.number;
                spindle_command();
                return true;
            case motion::ActionKind::Spindle:
                spindle_dir_ = a.value;
                spindle_command();
                return true;
            case motion::ActionKind::SpindleAtSpeed:
                return spindle_dir_ == 0 || spindle_at_speed_;
            case motion::ActionKind::ConditionalMove:
                return finish_probe();
            case motion::ActionKind::SpindleOrient:
                return orient_spindle(a, first);
            case motion::ActionKind::Coolant:
                coolant_flood_ = a.flag;
                if (!a.flag) coolant_mist_ = false;  // M09: all coolant off
                return true;
            case motion::ActionKind::ToolChange:
                return change_tool(a.value, first);
            case motion::ActionKind::SetToolNumber:
                tool_number_ = a.value;
                return true;
            case motion::ActionKind::ToolOffset:
                return set_tool_offset(a, line);
            case motion::ActionKind::SetOutput:
                digital_out_[static_cast<std::size_t>(a.value)] = a.flag;
                return true;
            case motion::ActionKind::WaitInput:
                return wait_input(a, line);
            case motion::ActionKind::Pause:
                return pause(first);
            case motion::ActionKind::OptionalPause:
                return !optional_stop_ || pause(first);
            case motion::ActionKind::Message:
                message_count_ = static_cast<std::uint32_t>(a.value);
                return true;
            case motion::ActionKind::MaskLimits:
                limits_masked_ = a.flag;
                limits_masked_pin_ = a.flag;
                return true;
            case motion::ActionKind::HomeDone:
                home_shift_mm_[static_cast<std::size_t>(a.value)] = a.number;
                return true;
            case motion::ActionKind::SpindleClamp:
                spindle_clamp_ = a.flag;
                return true;
            case motion::ActionKind::None:
                break;
        }
        return true;
    }

    // M03/M04/M05/S: the outputs change at once. spindle.0.at-speed is waited for by the
    // SpindleAtSpeed record the planner puts before the next feed move.
    void spindle_command() noexcept {
        spindle_orient_ = false;
        write_spindle();
    }

    std::uint64_t read_inputs() const noexcept {
        std::uint64_t bits = 0;
        for (std::size_t n = 0; n < num_dio_; ++n)
            if (digital_in_[n].get()) bits |= std::uint64_t{1} << n;
        return bits;
    }

    // G904: the sampler moves the axes; once they are all at rest the result goes to the
    // pin and to the planner thread, which plans the rest of the program from there.
    bool finish_probe() noexcept {
        const motion::ProbeJog& jog = sampler_->probe_jog();
        if (!jog.finished()) return false;
        probe_tripped_ = jog.tripped();
        const motion::AxisArray trip_mm = jog.trip_mm();
        hal::Out<double>* const pos_pins[motion::kProbeAxes] = {&probe_pos_x_, &probe_pos_y_,
                                                                &probe_pos_z_};
        for (int k = 0; k < motion::kProbeAxes; ++k) *pos_pins[k] = trip_mm[k] + home_shift_mm_[k];
        if (feeder_) feeder_->report_probe(jog.pos_mm(), trip_mm, jog.tripped());
        return true;
    }

    // M901 outputs synchronised with motion: due in the period their move starts.
    void apply_sync_outputs() noexcept {
        const motion::Sampler::SyncOutputs due = sampler_->take_sync_outputs();
        if (due.message > 0) message_count_ = due.message;
        if ((due.set | due.clear) == 0) return;
        for (std::size_t n = 0; n < num_dio_; ++n) {
            const std::uint64_t bit = std::uint64_t{1} << n;
            if (due.set & bit) digital_out_[n] = true;
            if (due.clear & bit) digital_out_[n] = false;
        }
    }

    // M19-like oriented stop: the spindle stops, orient is raised with the angle, and motion
    // waits for is-oriented. orient stays TRUE until the next spindle command.
    bool orient_spindle(const motion::Action& a, bool first) noexcept {
        if (first) {
            spindle_dir_ = 0;
            write_spindle();
            spindle_orient_angle_ = a.number;
            spindle_orient_ = true;
            return false;
        }
        return spindle_is_oriented_;
    }

    // LinuxCNC iocontrol's two handshakes: tool-prepare until tool-prepared, then tool-change
    // until tool-changed; tool-number takes the new tool and tool-prep-number returns to 0.
    bool change_tool(int tool, bool first) noexcept {
        if (first) {
            tool_prep_number_ = tool;
            tool_prepare_ = true;
            action_stage_ = 0;
            return false;
        }
        if (action_stage_ == 0) {
            if (!tool_prepared_) return false;
            tool_prepare_ = false;
            tool_change_ = true;
            action_stage_ = 1;
            return false;
        }
        if (!tool_changed_) return false;
        tool_change_ = false;
        tool_number_ = tool;
        tool_prep_number_ = 0;
        return true;
    }

    // G906 PLC[n] LEVEL l P t: waits for the level; past the timeout the program stops with an
    // error naming its line.
    bool wait_input(const motion::Action& a, std::int32_t line) noexcept {
        if (digital_in_[static_cast<std::size_t>(a.value)].get() == a.flag) return true;
        if (action_waited_s_ + 1e-9 < a.number) return false;
        program_fault_ = true;
        note_fault({FaultCause::WaitTimeout, 0, line, a});
        return false;  // the fault stop discards the queue, this action with it
    }

    // M00 (and M01 with motion.optional-stop): paused until motion.resume rises.
    bool pause(bool first) noexcept {
        if (first) {
            pausing_ = true;
            return false;
        }
        if (!resume_rose_) return false;
        pausing_ = false;
        return true;
    }

    // ---- joints and kinematics ----

    // G43/G49 (or M30's reset) while the machine stands on the action. A kinematics that uses
    // the tool length (TRT: motion.tooloffset.z => tool-offset) maps the same axis position
    // to other joints when it changes; with the table tilted they would jump by
    // (I - Ra) L z. That is refused as a program error before anything moves (LinuxCNC just
    // jumps); with the rotary axes at 0, or a kinematics that ignores the tool, nothing moves
    // and the offset is taken.
    bool set_tool_offset(const motion::Action& a, std::int32_t line) noexcept {
        const double before_mm = tool_offset_z_mm_;
        kins_.refresh();
        kins_.kins().inverse(action_pos_mm_, offset_before_mm_);
        tool_offset_z_ = a.number;  // the kinematics reads it through its tool-offset pin
        kins_.refresh();
        kins_.kins().inverse(action_pos_mm_, offset_after_mm_);
        double jump_mm = 0;
        int joint = 0;
        for (std::size_t j = 0; j < joint_count_; ++j) {
            const double d = std::fabs(offset_after_mm_[j] - offset_before_mm_[j]);
            if (d > jump_mm) {
                jump_mm = d;
                joint = static_cast<int>(j);
            }
        }
        if (jump_mm <= kToolOffsetJumpMm) {
            tool_offset_z_mm_ = a.number;
            return true;
        }
        tool_offset_z_ = before_mm;
        kins_.refresh();
        program_fault_ = true;
        note_fault({FaultCause::ToolOffsetJump, joint, line, a, jump_mm});
        return false;  // the fault stop discards the queue, this action with it
    }

    static constexpr double kToolOffsetJumpMm = 1e-6;

    // The module's parameters (TRT pivots, tool offset) into this period's kinematics. An
    // instance unloaded under a running machine leaves no geometry to trust: fault stop.
    void check_kinematics() noexcept {
        if (kins_.refresh() || kins_lost_) return;
        kins_lost_ = true;
        note_fault({FaultCause::KinsLost, 0, last_line_, {}});
        for (std::size_t j = 0; j < joint_count_; ++j) amp_enable_out_[j] = false;
    }

    // Joint velocity and acceleration of the commands (backward differences), published on
    // joint.N.vel-cmd / acc-cmd and checked against joint.N.max-velocity / max-acceleration.
    // The planner limits the axes, and the joints too when the kinematics is linear (trivial,
    // gantry, CoreXY: planner_config()); a nonlinear kinematics can still ask more of a motor
    // (a tilted table swings the linear joints), so excesses are recorded and printed at stop,
    // not tripped on.
    void check_joint_motion(double dt, std::int32_t line) noexcept {
        if (!(dt > 0)) return;
        if (!joints_primed_) {
            // Before the first period the joints stood where the sampler starts (the planner's
            // origin), at rest: a move in the very first period counts from there (taking the
            // first command as the start saw 1.5 times the acceleration in the second period).
            kins_.kins().inverse(motion::AxisArray{}, joint_prev_mm_);
            std::fill(joint_vel_mm_s_.begin(), joint_vel_mm_s_.end(), 0.0);
            joints_primed_ = true;
        }
        for (std::size_t j = 0; j < joint_count_; ++j) {
            const double vel = (joint_cmd_mm_[j] - joint_prev_mm_[j]) / dt;
            const double acc = (vel - joint_vel_mm_s_[j]) / dt;
            joint_vel_mm_s_[j] = vel;
            joint_prev_mm_[j] = joint_cmd_mm_[j];
            joint_vel_cmd_[j] = vel;
            joint_acc_cmd_[j] = acc;
            note_excess(joint_excess_[j].vel, std::fabs(vel), joint_max_velocity_[j].get(), line);
            note_excess(joint_excess_[j].acc, std::fabs(acc), joint_max_acceleration_[j].get(),
                        line);
        }
    }

    // joint.N.min-limit / max-limit (LinuxCNC's [JOINT_N]MIN_LIMIT / MAX_LIMIT) on the joint
    // commands after the inverse kinematics: the planner keeps the axes inside their limits,
    // but a kinematics can take a motor past its travel from inside them (a CoreXY motor runs
    // X + Y). A command beyond a limit and further out than last period's trips a limit fault:
    // the fault stop, program abandoned. A joint standing outside (after a reset) may move back.
    // Reads the params every period, like the velocity limits. The caller drops the amps.
    void check_joint_limits(bool enabled, std::int32_t line) noexcept {
        if (!enabled || limit_fault_) return;
        for (std::size_t j = 0; j < joint_count_; ++j) {
            const double cmd_mm = joint_cmd_mm_[j];
            const double step_mm = cmd_mm - joint_prev_mm_[j];
            const double min_mm = joint_min_limit_[j].get(), max_mm = joint_max_limit_[j].get();
            const bool out_high = cmd_mm > max_mm + kJointLimitRoundingMm && step_mm > 0;
            const bool out_low = cmd_mm < min_mm - kJointLimitRoundingMm && step_mm < 0;
            if (!(out_high || out_low)) continue;
            limit_fault_ = true;
            FaultReport report{FaultCause::JointSoftLimit, static_cast<int>(j), line, {}};
            report.amount = cmd_mm;
            report.min_mm = min_mm;
            report.max_mm = max_mm;
            note_fault(report);
            return;
        }
    }

    // A path planned along a joint limit (a CoreXY line of constant X + Y on motor A's limit)
    // sums sampled axes that can round a few ulps past it.
    static constexpr double kJointLimitRoundingMm = 1e-9;

    // Relative slack for sampling: backward differences of an exactly limited profile can read
    // a hair above the limit.
    static constexpr double kJointLimitSlack = 1e-3;

    struct Excess {
        std::uint32_t periods = 0;
        double peak = 0;
        double limit = 0;
        std::int32_t first_line = 0;
    };
    struct JointExcess {
        Excess vel, acc;
    };

    static void note_excess(Excess& e, double value, double limit, std::int32_t line) noexcept {
        if (!(limit > 0) || !(value > limit * (1 + kJointLimitSlack))) return;
        if (e.periods++ == 0) e.first_line = line;
        e.peak = std::max(e.peak, value);
        e.limit = limit;
    }

    void write_axis_feedback(const motion::AxisArray& cmd_mm) noexcept {
        for (std::size_t j = 0; j < joint_count_; ++j) joint_fb_mm_[j] = motor_pos_fb_[j].get();
        motion::AxisArray fb_mm = cmd_mm;  // axes the kinematics lacks keep their command
        kins_.kins().forward(joint_fb_mm_, fb_mm);
        for (const AxisPins& a : axes_) *a.pos_fb = fb_mm[a.axis] + home_shift_mm_[a.axis];
    }

    // Printed once, at the first stop or unload after the run.
    void report_joint_excess() {
        if (excess_reported_) return;
        for (std::size_t j = 0; j < joint_excess_.size(); ++j) {
            auto say = [&](const Excess& e, const char* what, const char* per, const char* param) {
                if (e.periods == 0) return;
                excess_reported_ = true;
                fmt::print(stderr,
                           "{}: joint {} was commanded {} of {:.6g}{} in {} periods (first at "
                           "line {}), above {} = {:.6g}: {}\n",
                           name(), j, what, e.peak, per, e.periods, e.first_line,
                           pin_name(fmt::format("joint.{}.{}", j, param)), e.limit,
                           joints_planned_ ? "the planner keeps the motors within the limits "
                                             "they had at start; one lowered since is only "
                                             "checked"
                                           : "the kinematics ask more of this motor than the "
                                             "axis limits allow");
            };
            say(joint_excess_[j].vel, "a velocity", "/s", "max-velocity");
            say(joint_excess_[j].acc, "an acceleration", "/s^2", "max-acceleration");
        }
    }

    // Joint commands, following errors and amp enables; true if a drive reports a fault or a
    // following error exceeds its limit while enabled (the first such joint is noted, with
    // `line`, the line running).
    bool write_joints(bool enabled, std::int32_t line) noexcept {
        bool fault = false;
        for (std::size_t j = 0; j < joint_count_; ++j) {
            motor_pos_cmd_[j] = joint_cmd_mm_[j];
            const double ferror = joint_cmd_mm_[j] - motor_pos_fb_[j].get();
            const double limit = max_ferror_[j].get();
            const bool errored = limit > 0 && std::fabs(ferror) > limit;
            const bool amp_fault = amp_fault_in_[j].get();
            f_error_[j] = ferror;
            f_error_lim_[j] = limit;
            f_errored_[j] = errored;
            amp_enable_out_[j] = enabled && !kins_lost_;
            // A disabled machine may sit anywhere: only an enabled one trips.
            if (!enabled || fault || !(errored || amp_fault)) continue;
            fault = true;
            FaultReport report;
            report.cause = amp_fault ? FaultCause::AmpFault : FaultCause::FollowingError;
            report.joint = static_cast<int>(j);
            report.line = line;
            report.amount = ferror;
            report.max_mm = limit;
            note_fault(report);
        }
        return fault;
    }

    // An error met while the program was already running has only the fault pin in realtime;
    // its text goes to motion.messages (above) and, for a reader-less instance (halrun), to
    // stderr here, in the configuration world, at stop, so a HAL file's output keeps its order.
    // Called after the producer thread is joined, so this world is motion.messages' producer
    // now: faults not published yet (they came after the join) go out from here. Then each
    // error a reader has not taken from the stream is printed once; one a reader took (`cnc
    // run` does, and prints it itself) is not, so it is told once.
    void report_late_error() {
        publish_faults();
        const std::uint64_t taken = records_pushed_ - messages_.used();
        for (const SentError& e : errors_)
            if (e.taken_at == 0 || taken < e.taken_at)
                fmt::print(stderr, "{}: {}\n", name(), e.text);
        errors_.clear();
        const std::uint32_t lost = faults_lost_.exchange(0, std::memory_order_relaxed);
        if (lost > 0)
            fmt::print(stderr, "{}: {} more fault(s) came too fast to be reported\n", name(), lost);
    }

    // Faults of a program action or move, at its line (FaultReport::line): a following error
    // is the path of the line running not being followed. A switch, the e-stop or a drive's own
    // fault is the machine's, whatever line runs.
    static bool names_line(FaultCause c) {
        return c == FaultCause::WaitTimeout || c == FaultCause::ToolOffsetJump ||
               c == FaultCause::JointSoftLimit || c == FaultCause::FollowingError;
    }

    // Why, without the place (names_line() tells whether the fault has one).
    std::string fault_cause(const FaultReport& r) const {
        switch (r.cause) {
            case FaultCause::EStop:
                return fmt::format("e-stop: {} went FALSE; motion stopped, program abandoned",
                                   pin_name("iocontrol.0.emc-enable-in"));
            case FaultCause::PosLimit:
            case FaultCause::NegLimit: {
                const bool pos = r.cause == FaultCause::PosLimit;
                return fmt::format(
                    "joint {} hit its {} limit switch ({}); motion stopped, program abandoned",
                    r.joint, pos ? "positive" : "negative",
                    pin_name(fmt::format("joint.{}.{}-lim-sw-in", r.joint, pos ? "pos" : "neg")));
            }
            case FaultCause::WaitTimeout:
                return fmt::format("G906: {} did not become {} within {} s",
                                   pin_name(fmt::format("motion.digital-in-{:02}", r.action.value)),
                                   r.action.flag ? "TRUE" : "FALSE", r.action.number);
            case FaultCause::ToolOffsetJump:
                return fmt::format(
                    "the tool length offset changes to {} mm while the kinematics use it: joint {} "
                    "would jump {:.4f} mm (the table is tilted); change the tool offset (G43/G49, "
                    "and M30's reset) with the rotary axes at 0; motion stopped, program "
                    "abandoned",
                    r.action.number, r.joint, r.amount);
            case FaultCause::JointSoftLimit: {
                // A joint that drives A, B or C turns (degrees).
                const int axis = kins_.kins().joint_axes()[static_cast<std::size_t>(r.joint)];
                const char* unit = axis >= 3 && axis <= 5 ? "deg" : "mm";
                return fmt::format(
                    "joint {} commanded to {:.4f} {}, beyond its soft limit [{:g}, {:g}] {} ({}); "
                    "motion stopped, program abandoned",
                    r.joint, r.amount, unit, r.min_mm, r.max_mm, unit,
                    pin_name(fmt::format("joint.{}.{}-limit", r.joint,
                                         r.amount > r.max_mm ? "max" : "min")));
            }
            case FaultCause::FollowingError:
                return fmt::format(
                    "joint {} following error {:.4f} mm, over its limit {} = {:g} mm; motion "
                    "stopped, program abandoned",
                    r.joint, r.amount, pin_name(fmt::format("joint.{}.max-ferror", r.joint)),
                    r.max_mm);
            case FaultCause::AmpFault:
                return fmt::format("joint {} drive fault ({}); motion stopped, program abandoned",
                                   r.joint,
                                   pin_name(fmt::format("joint.{}.amp-fault-in", r.joint)));
            case FaultCause::KinsLost:
                return fmt::format(
                    "the kinematics kins={} was unloaded while motion used it; motion stopped, "
                    "program abandoned",
                    kins_.name());
            case FaultCause::None:
                break;
        }
        return "";
    }

    // The full name of one of this instance's pins, for messages.
    std::string pin_name(std::string_view n) const {
        const std::string p = pin(n);
        return p[0] == '=' ? p.substr(1) : fmt::format("{}.{}", name(), p);
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

    // kins=NAME: the machine's kinematics module, loaded before motion; else the built-in
    // trivial kinematics of coordinates= (or num_joints=).
    // kins=auto (what `loadrt motmod` gives): the one instance loaded, else the built-in.
    motioncomp::KinsLink link_kinematics() const {
        check_linuxcnc_args();
        const auto kins = arg("kins");
        if (!kins) return motioncomp::KinsLink::builtin(read_coordinates());
        auto link = *kins == "auto" ? motioncomp::KinsLink::automatic(read_coordinates())
                                    : motioncomp::KinsLink::find(*kins);
        if (!link.from_module()) return link;
        // LinuxCNC: `trivkins` (all nine letters) with num_joints=3 is an XYZ machine.
        if (const long n = arg_int("num_joints", 0); n > 0)
            link.keep_first_joints_of_identity(static_cast<std::size_t>(n));
        if (const auto c = arg("coordinates")) {
            const std::string want = axis_letters(link.kins());
            std::string given = upper(*c);
            std::sort(given.begin(), given.end(), [](char a, char b) {
                return motion::axis_index(a) < motion::axis_index(b);
            });
            given.erase(std::unique(given.begin(), given.end()), given.end());
            if (given != want)
                throw hal::Error(fmt::format(
                    "coordinates={} does not match kins={}, whose joints drive the axes {}", *c,
                    link.name(), want));
        }
        return link;
    }

    // The axes a kinematics drives, once each, in XYZABCUVW order.
    static std::string axis_letters(const motion::Kinematics& k) {
        std::string out;
        for (int axis = 0; axis < motion::kAxes; ++axis)
            for (int a : k.joint_axes())
                if (a == axis) {
                    out += kUpperAxes[axis];
                    break;
                }
        return out;
    }

    // coordinates= as given for the built-in kinematics (a gantry's XYYZ), else the axes the
    // module's joints drive.
    std::string machine_coordinates() const {
        return kins_.from_module() ? axis_letters(kins_.kins()) : read_coordinates();
    }

    // LinuxCNC motmod's module parameters that have no counterpart here (see motion.md,
    // Loading as motmod): periods of threads this component does not make, the shared-memory
    // key of a user-space link it does not have. Ones that would change the machine are
    // accepted only at the value that means what we do.
    void check_linuxcnc_args() const {
        for (const char* ignored : {"base_period_nsec", "traj_period_nsec", "key", "base_thread_fp"})
            (void)arg_int(ignored, 0);  // still checked: a number, as LinuxCNC's loader wants
        if (const long n = arg_int("num_spindles", 1); n != 1)
            throw hal::Error(fmt::format("num_spindles={}: motion has one spindle (spindle.0)", n));
        if (const long n = arg_int("num_aio", 4); n < 1 || n > kMaxDio)
            throw hal::Error(fmt::format("num_aio={}: must be 1 to {}", n, kMaxDio));
        if (const long m = arg_int("unlock_joints_mask", 0); m != 0)
            throw hal::Error(fmt::format(
                "unlock_joints_mask={}: motion has no locking rotary joints (joint.N.unlock)", m));
    }

    std::size_t ring_capacity() const {
        const long n = arg_int("queue", 4096);
        if (n < 2 || n > (1L << 20))
            throw hal::Error(fmt::format("queue={}: must be 2 to {} records", n, 1L << 20));
        return static_cast<std::size_t>(n);
    }

    std::size_t read_num_dio() const {
        const long n = arg_int("num_dio", 4);
        if (n < 1 || n > kMaxDio)
            throw hal::Error(fmt::format("num_dio={}: must be 1 to {}", n, kMaxDio));
        return static_cast<std::size_t>(n);
    }

    // Soft limits and I/O counts, read at start() like the planner's limits. The joint limits
    // are checked again every servo period (check_joint_limits), with the params as they are
    // then.
    motioncomp::SinkConfig sink_config() const {
        motioncomp::SinkConfig c;
        c.min_limit_mm.fill(-1e99);
        c.max_limit_mm.fill(1e99);
        for (const AxisPins& a : axes_) {
            c.min_limit_mm[a.axis] = a.min_limit->get();
            c.max_limit_mm[a.axis] = a.max_limit->get();
            if (!(c.min_limit_mm[a.axis] <= c.max_limit_mm[a.axis]))
                throw hal::Error(fmt::format("{}: axis.{}: min-limit {} is above max-limit {}",
                                             name(), kLowerAxes[a.axis], c.min_limit_mm[a.axis],
                                             c.max_limit_mm[a.axis]));
        }
        c.joints.kins = kins_.planning_copy();
        for (std::size_t j = 0; j < joint_count_; ++j) {
            c.joints.min_limit.push_back(joint_min_limit_[j].get());
            c.joints.max_limit.push_back(joint_max_limit_[j].get());
            if (!(c.joints.min_limit[j] <= c.joints.max_limit[j]))
                throw hal::Error(fmt::format("{}: joint.{}: min-limit {} is above max-limit {}",
                                             name(), j, c.joints.min_limit[j],
                                             c.joints.max_limit[j]));
        }
        c.joints.pin_stem = pin_name("joint");
        // The planner limits a linear kinematics' joints itself (planner_config()); any other
        // kinematics' joint rates are planned by the sink, move by move (joint_limits.hpp).
        if (kins_.kins().linear_map().empty()) {
            for (std::size_t j = 0; j < joint_count_; ++j) {
                c.joints.max_velocity.push_back(joint_max_velocity_[j].get());
                c.joints.max_acceleration.push_back(joint_max_acceleration_[j].get());
            }
            c.joints.max_rate = kMaxOverride;
        }
        c.digital_outputs = static_cast<int>(num_dio_);
        c.digital_inputs = static_cast<int>(num_dio_);
        return c;
    }

    void check_num_joints() const {
        const long n = arg_int("num_joints", static_cast<long>(joint_count_));
        if (n == static_cast<long>(joint_count_)) return;
        if (kins_.from_module())
            throw hal::Error(fmt::format("num_joints={} does not match kins={} ({} joints)", n,
                                         kins_.name(), joint_count_));
        throw hal::Error(
            fmt::format("num_joints={} does not match coordinates={} ({} joints, one per letter)",
                        n, coordinates_, joint_count_));
    }

    void make_axis_pins() {
        for (int k = 0; k < motion::kAxes; ++k) {
            if (coordinates_.find(kUpperAxes[k]) == std::string::npos) continue;
            const std::string stem = pin(fmt::format("axis.{}", kLowerAxes[k]));
            AxisPins a;
            a.axis = k;
            a.pos_cmd = std::make_unique<hal::Out<double>>(this, stem + ".pos-cmd");
            a.pos_fb = std::make_unique<hal::Out<double>>(this, stem + ".pos-fb");
            a.home_shift = std::make_unique<hal::Out<double>>(this, stem + ".home-shift");
            a.max_velocity =
                std::make_unique<hal::Param<double>>(this, stem + ".max-velocity", 100.0);
            a.max_acceleration =
                std::make_unique<hal::Param<double>>(this, stem + ".max-acceleration", 1000.0);
            a.max_jerk = std::make_unique<hal::Param<double>>(this, stem + ".max-jerk", 0.0);
            // LinuxCNC's defaults for an axis without MIN_LIMIT / MAX_LIMIT.
            a.min_limit = std::make_unique<hal::Param<double>>(this, stem + ".min-limit", -1e99);
            a.max_limit = std::make_unique<hal::Param<double>>(this, stem + ".max-limit", 1e99);
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
        // Not 1e9 each: the sampler's rate limits take the smallest acc / vel ratio over all
        // axes, and 1e9 / 1e9 made resuming from a hold ten times slower than planned.
        double loosest_vel = 0, loosest_acc = 0;
        for (const AxisPins& a : axes_) {
            loosest_vel = std::max(loosest_vel, a.max_velocity->get());
            loosest_acc = std::max(loosest_acc, a.max_acceleration->get());
        }
        for (int k = 0; k < motion::kAxes; ++k) {
            if (coordinates_.find(kUpperAxes[k]) != std::string::npos) continue;
            plan.limits.vel_mm_s[k] = loosest_vel;
            plan.limits.acc_mm_s2[k] = loosest_acc;
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
        add_joint_limits(plan.limits);
        return plan;
    }

    // A linear kinematics' joints are planned with their limits (joint.N.max-velocity,
    // max-acceleration, max-jerk; 0 = unlimited), as the axes are with theirs.
    void add_joint_limits(motion::AxisLimits& limits) const {
        const std::vector<motion::AxisArray> rows = kins_.kins().linear_map();
        if (rows.empty()) return;
        std::vector<motion::JointLimit> joints(joint_count_);
        for (std::size_t j = 0; j < joint_count_; ++j) {
            joints[j] = {joint_max_velocity_[j].get(), joint_max_acceleration_[j].get(),
                         joint_max_jerk_[j].get()};
            const std::pair<const char*, double> given[] = {
                {"max-velocity", joints[j].vel_mm_s},
                {"max-acceleration", joints[j].acc_mm_s2},
                {"max-jerk", joints[j].jerk_mm_s3}};
            for (const auto& [param, value] : given)
                if (!(value >= 0) || !std::isfinite(value))
                    throw hal::Error(
                        fmt::format("{}: {} = {}: a joint limit must be >= 0 (0 = unlimited)",
                                    name(), pin_name(fmt::format("joint.{}.{}", j, param)), value));
        }
        try {
            motion::set_linear_joints(limits, rows, joints);
        } catch (const std::invalid_argument& e) {
            throw hal::Error(fmt::format(
                "{}: joint.N.max-velocity / max-acceleration / max-jerk: {}", name(), e.what()));
        }
    }

    motioncomp::KinsLink kins_;
    std::string coordinates_;
    std::size_t joint_count_;

    hal::Array<hal::Out<double>> motor_pos_cmd_;
    hal::Array<hal::In<double>> motor_pos_fb_;
    hal::Array<hal::Out<double>> f_error_;
    hal::Array<hal::Out<bool>> amp_enable_out_;
    hal::Array<hal::In<bool>> amp_fault_in_{this, pin("joint.{}.amp-fault-in"), joint_count_};
    hal::Array<hal::Out<double>> f_error_lim_{this, pin("joint.{}.f-error-lim"), joint_count_};
    hal::Array<hal::Out<bool>> f_errored_{this, pin("joint.{}.f-errored"), joint_count_};
    hal::Array<hal::Param<double>> max_ferror_{this, pin("joint.{}.max-ferror"), joint_count_};
    hal::Array<hal::Out<double>> joint_vel_cmd_{this, pin("joint.{}.vel-cmd"), joint_count_};
    hal::Array<hal::Out<double>> joint_acc_cmd_{this, pin("joint.{}.acc-cmd"), joint_count_};
    // LinuxCNC's [JOINT_N]MAX_VELOCITY / MAX_ACCELERATION; 0 = unlimited. Planned with when the
    // kinematics is linear, and checked as commanded (excesses reported at stop).
    hal::Array<hal::Param<double>> joint_max_velocity_{this, pin("joint.{}.max-velocity"),
                                                       joint_count_};
    hal::Array<hal::Param<double>> joint_max_acceleration_{
        this, pin("joint.{}.max-acceleration"), joint_count_};
    // [JOINT_N]MAX_JERK; 0 = unlimited. Planned with (as the velocity and acceleration limits
    // are) when the kinematics is linear; not checked as commanded.
    hal::Array<hal::Param<double>> joint_max_jerk_{this, pin("joint.{}.max-jerk"), joint_count_};
    // LinuxCNC's [JOINT_N]MIN_LIMIT / MAX_LIMIT and its defaults for a joint without them.
    hal::Array<hal::Param<double>> joint_min_limit_{this, pin("joint.{}.min-limit"), joint_count_,
                                                    -1e99};
    hal::Array<hal::Param<double>> joint_max_limit_{this, pin("joint.{}.max-limit"), joint_count_,
                                                    1e99};
    hal::Array<hal::In<bool>> pos_lim_sw_in_{this, pin("joint.{}.pos-lim-sw-in"), joint_count_};
    hal::Array<hal::In<bool>> neg_lim_sw_in_{this, pin("joint.{}.neg-lim-sw-in"), joint_count_};
    // Published for LinuxCNC HAL files; homing is not implemented yet, so nothing reads it.
    hal::Array<hal::In<bool>> home_sw_in_{this, pin("joint.{}.home-sw-in"), joint_count_};
    std::vector<AxisPins> axes_;
    std::size_t num_dio_;
    hal::Array<hal::Out<bool>> digital_out_;
    hal::Array<hal::In<bool>> digital_in_;

    // LinuxCNC motion's spindle 0.
    hal::Out<double> spindle_speed_out_{this, pin("spindle.0.speed-out")};
    hal::Out<double> spindle_speed_out_abs_{this, pin("spindle.0.speed-out-abs")};
    hal::Out<bool> spindle_on_{this, pin("spindle.0.on")};
    hal::Out<bool> spindle_forward_{this, pin("spindle.0.forward")};
    hal::Out<bool> spindle_reverse_{this, pin("spindle.0.reverse")};
    hal::In<bool> spindle_at_speed_{this, pin("spindle.0.at-speed"), true};
    hal::Out<bool> spindle_orient_{this, pin("spindle.0.orient")};
    hal::Out<double> spindle_orient_angle_{this, pin("spindle.0.orient-angle")};
    hal::In<bool> spindle_is_oriented_{this, pin("spindle.0.is-oriented")};

    // LinuxCNC iocontrol's pins.
    hal::Out<bool> coolant_flood_{this, pin("iocontrol.0.coolant-flood")};
    hal::Out<bool> coolant_mist_{this, pin("iocontrol.0.coolant-mist")};
    hal::Out<std::int32_t> tool_prep_number_{this, pin("iocontrol.0.tool-prep-number")};
    hal::Out<bool> tool_prepare_{this, pin("iocontrol.0.tool-prepare")};
    hal::In<bool> tool_prepared_{this, pin("iocontrol.0.tool-prepared")};
    hal::Out<bool> tool_change_{this, pin("iocontrol.0.tool-change")};
    hal::In<bool> tool_changed_{this, pin("iocontrol.0.tool-changed")};
    hal::Out<std::int32_t> tool_number_{this, pin("iocontrol.0.tool-number")};
    // LinuxCNC motion's tool length offset in Z; a TRT config nets it to kins.tool-offset.
    hal::Out<double> tool_offset_z_{this, pin("motion.tooloffset.z")};
    // TRUE by default (unlike LinuxCNC's) so a config without an e-stop chain runs.
    hal::In<bool> emc_enable_in_{this, pin("iocontrol.0.emc-enable-in"), true};
    hal::Out<bool> user_enable_out_{this, pin("iocontrol.0.user-enable-out"), true};

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
    hal::In<bool> optional_stop_{this, pin("motion.optional-stop")};
    hal::In<bool> single_block_{this, pin("motion.single-block")};
    hal::In<bool> resume_{this, pin("motion.resume")};
    hal::Out<bool> program_paused_{this, pin("motion.program-paused")};
    hal::Out<bool> probe_tripped_{this, pin("motion.probe-tripped")};
    // Where the last G904's inputs came (machine coordinates of X Y Z; where the axis stopped
    // if its input never came): LinuxCNC's probed position, net to interp.probe-pos-L.
    hal::Out<double> probe_pos_x_{this, pin("motion.probe-pos-x")};
    hal::Out<double> probe_pos_y_{this, pin("motion.probe-pos-y")};
    hal::Out<double> probe_pos_z_{this, pin("motion.probe-pos-z")};
    hal::Out<std::uint32_t> message_count_{this, pin("motion.message-count")};
    // Texts (messages, warnings, the error) motion.messages had no room for: nobody reads it.
    hal::Out<std::uint32_t> message_dropped_{this, pin("motion.message-dropped")};
    hal::Out<bool> limits_masked_pin_{this, pin("motion.limits-masked")};
    hal::Out<bool> spindle_clamp_{this, pin("spindle.0.clamp")};
    hal::Param<double> blend_tolerance_mm_{this, pin("motion.blend-tolerance"), 0.01};

    motion::SpscRing<motion::PreparedSegment> ring_;
    std::unique_ptr<motion::Sampler> sampler_;
    std::unique_ptr<motioncomp::ProgramFeeder> feeder_;
    std::optional<hal::Stream> canon_;                // canon=: the interp component's stream
    hal::Stream messages_;                            // motion.messages: M801 texts and warnings
    // motion.messages' producer only (see publish_text).
    interp::wire::Encoder text_encoder_;
    std::vector<interp::wire::Record> text_records_;
    std::uint64_t records_pushed_ = 0;
    // The errors sent (or dropped) since the last stop, with their stderr texts, for
    // report_late_error().
    struct SentError {
        std::string text;
        std::uint64_t taken_at = 0;  // records_pushed_ with it in; 0: not on the stream
    };
    std::vector<SentError> errors_;
    // Faults the servo function noted, to the stream's producer (it pops). Preallocated.
    static constexpr std::size_t kFaultReports = 8;
    motion::SpscRing<FaultReport> faults_{kFaultReports};
    std::atomic<std::uint32_t> faults_lost_{0};  // notes faults_ had no room for
    hal::Worker fault_poller_;  // without a feeder: the producer from start() to stop()
    std::atomic<std::uint32_t> dropped_texts_{0};  // the producer adds, the servo function reads
    motion::AxisArray home_shift_mm_{};  // machine coordinate minus planner frame (M902)
    bool limits_masked_ = false;         // M802 P131072 until P131073
    hal::Out<std::uint32_t> canon_sync_{this, pin("motion.canon-sync")};
    std::string program_path_;
    machine_program::Options program_options_;  // ini= and dialect=, for program=
    double servo_period_s_ = 1e-3;
    std::vector<double> joint_cmd_mm_;
    std::vector<double> joint_fb_mm_;    // scratch for forward()
    std::vector<double> joint_prev_mm_;  // last period's joint command
    std::vector<double> joint_vel_mm_s_;
    std::vector<JointExcess> joint_excess_;
    bool joints_primed_ = false;   // joint_prev_mm_ and joint_vel_mm_s_ hold the last period's
    bool joints_planned_ = false;  // the planner has the joints' limits (a linear kinematics)
    bool excess_reported_ = false;
    bool enable_now_ = false;      // motion.enable as taken by take_commands() this period
    bool commands_taken_ = false;  // take_commands() ran since the last motion-controller
    bool kins_lost_ = false;  // latched for good: the geometry is gone
    motion::AxisArray action_pos_mm_{};  // this period's sampled position
    double tool_offset_z_mm_ = 0;        // motion.tooloffset.z as last written
    std::vector<double> offset_before_mm_, offset_after_mm_;  // scratch for set_tool_offset
    bool abort_seen_ = false;
    bool fault_seen_ = false;
    bool stop_seen_ = false;  // an abort or a fault stop was requested last period
    bool enable_seen_ = false;
    bool resume_seen_ = false;
    bool resume_rose_ = false;
    bool drive_fault_ = false;    // latched until motion.enable rises again
    bool limit_fault_ = false;    // likewise
    bool program_fault_ = false;  // a G906 timed out: latched for good, like a planner error
    EStop estop_ = EStop::Resetting;  // ready as soon as emc-enable-in reads TRUE
    std::vector<char> pos_lim_seen_, neg_lim_seen_;  // last values, for rising edges
    std::vector<double> lim_prev_cmd_mm_;            // joint commands of the period before last
    std::int32_t last_line_ = 0;  // motion.program-line as last written
    std::uint32_t starved_count_ = 0;
    bool lockstep_ = false;  // wait for the planner each period (simulated clock only)

    // Machine-command state.
    int spindle_dir_ = 0;  // 1 forward, -1 reverse, 0 stopped
    double spindle_rpm_ = 0;
    bool pausing_ = false;  // in an M00 / M01 pause
    bool action_started_ = false;
    int action_stage_ = 0;
    double action_waited_s_ = 0;
};

}  // namespace

HAL_COMPONENT(motion, Motion, "Trajectory planner and servo-rate motion controller", "num_joints",
              "coordinates", "kins", "program", "canon", "ini", "dialect", "settings_dir", "servo_period_nsec", "queue", "sim_lockstep",
              "num_dio", "base_period_nsec", "traj_period_nsec", "num_aio", "num_spindles", "key",
              "base_thread_fp", "unlock_joints_mask")
