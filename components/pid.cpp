// pid: LinuxCNC's PID loop with feed-forward and relay auto-tuning (`loadrt pid
// [num_chan=N | names=a,b] [debug=1]`, function <name>.do-pid-calcs), pin for pin.
//
// One cycle, in order (all limits are "no limit" when zero):
//   error   = command - feedback            (prev_command - feedback when
//                                            error-previous-target, see below)
//   e       = error clamped to +-maxerror, then shrunk towards 0 by deadband
//   errorI += e * period      (only while enabled and not pushing further into saturation;
//                              clamped to +-maxerrorI; reset to 0 while disabled)
//   errorD  = command-deriv - feedback-deriv, clamped to +-maxerrorD
//   commandD = command-deriv clamped to +-maxcmdD; commandDD and commandDDD are backward
//              differences of commandD and commandDD, clamped to +-maxcmdDD / +-maxcmdDDD
//   output  = bias + Pgain*e + Igain*errorI + Dgain*errorD
//           + FF0*command + FF1*commandD + FF2*commandDD + FF3*commandDDD,
//             clamped to +-maxoutput (0 while disabled)
//
// command-deriv and feedback-deriv: while unlinked, pid writes its own backward-difference
// estimate into the pin's own storage each cycle (so getp shows it); once a signal is linked
// the signal's value is used instead (LinuxCNC's "dummysig" idiom). On the falling edge of
// index-enable the estimates and the previous-target error are skipped for one cycle, so an
// encoder index reset does not spike FF1 or D.
//
// error-previous-target (default TRUE, as in LinuxCNC 2.9) measures the error against the
// previous cycle's command, which is what the motion controller compares with.
//
// Auto-tuning (tune-mode, tune-start): the relay method of Astrom and Hagglund. pid drives
// output = bias +- |tune-effort| by the sign of the error, measures the mean amplitude A and
// the period Pu of the resulting limit cycle over tune-cycles half cycles, and sets
//   Ku = 4 |tune-effort| / (pi A)
//   tune-type 0: Pgain = 0.6 Ku,  Igain = 1.2 Ku / Pu,  Dgain = 0.075 Ku Pu, FF1 = 0
//   tune-type 1: Pgain = 0.45 Ku, Igain = 0.54 Ku / Pu, Dgain = 0,           FF1 = 1
// and FF0 = FF2 = 0 (Ziegler-Nichols). The results are written into the gain pins' own
// storage: an unlinked gain pin shows them, a gain pin linked to a signal keeps following its
// signal (the bus allows one writer per signal; LinuxCNC would overwrite the signal).
//
// Differences from LinuxCNC, all in corner cases: saturation is cleared when maxoutput is set
// to 0 (LinuxCNC keeps the last limit state, so `saturated` could stay TRUE forever), and
// tune-cycles = 0 ends a tuning run at once instead of dividing by zero.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string_view>

#include "hal/component.hpp"

namespace {

double clamp_symmetric(double value, double limit) noexcept {
    if (limit == 0.0) return value;  // 0 means "no limit" for every max* pin
    if (value > limit) return limit;
    if (value < -limit) return -limit;
    return value;
}

double apply_deadband(double value, double deadband) noexcept {
    if (value > deadband) return value - deadband;
    if (value < -deadband) return value + deadband;
    return 0.0;
}

enum class TuneState { Pid, Idle, Start, Positive, Negative, Abort };

struct Pid : hal::Instance {
    hal::In<bool> enable{this, "enable"};
    hal::In<double> command{this, "command"};
    hal::SelfWritableIn<double> command_deriv{this, "command-deriv"};
    hal::In<double> feedback{this, "feedback"};
    hal::SelfWritableIn<double> feedback_deriv{this, "feedback-deriv"};
    hal::Out<double> error{this, "error"};
    hal::Out<double> output{this, "output"};
    hal::Out<bool> saturated{this, "saturated"};
    hal::Out<double> saturated_s{this, "saturated-s"};
    hal::Out<std::int32_t> saturated_count{this, "saturated-count"};
    hal::SelfWritableIn<double> pgain{this, "Pgain", 1.0};
    hal::SelfWritableIn<double> igain{this, "Igain"};
    hal::SelfWritableIn<double> dgain{this, "Dgain"};
    hal::SelfWritableIn<double> ff0{this, "FF0"};
    hal::SelfWritableIn<double> ff1{this, "FF1"};
    hal::SelfWritableIn<double> ff2{this, "FF2"};
    hal::In<double> ff3{this, "FF3"};
    hal::In<double> deadband{this, "deadband"};
    hal::In<double> maxerror{this, "maxerror"};
    hal::In<double> maxerror_i{this, "maxerrorI"};
    hal::In<double> maxerror_d{this, "maxerrorD"};
    hal::In<double> maxcmd_d{this, "maxcmdD"};
    hal::In<double> maxcmd_dd{this, "maxcmdDD"};
    hal::In<double> maxcmd_ddd{this, "maxcmdDDD"};
    hal::In<double> bias{this, "bias"};
    hal::In<double> maxoutput{this, "maxoutput"};
    hal::In<bool> index_enable{this, "index-enable"};
    hal::In<bool> error_previous_target{this, "error-previous-target", true};
    hal::IO<double> tune_effort{this, "tune-effort", 0.5};
    hal::IO<std::uint32_t> tune_cycles{this, "tune-cycles", 50};
    hal::IO<std::uint32_t> tune_type{this, "tune-type", 0};
    hal::In<bool> tune_mode{this, "tune-mode"};
    hal::IO<bool> tune_start{this, "tune-start"};

    Pid() {
        const long debug = arg_int("debug", 0);
        if (debug < 0)  // LinuxCNC treats any positive value as 1
            throw hal::Error("debug=" + std::to_string(debug) +
                             ": must be 0 (off) or 1 (export the internal terms)");
        if (debug > 0) {
            // LinuxCNC exports the internal terms as output pins only with debug=1.
            debug_.emplace(this);
        }
        function<&Pid::update>("do-pid-calcs");
    }

    void update(hal::Period period) noexcept {
        if (tune_ != TuneState::Pid) {
            auto_tune(period);
        } else {
            calculate(period);
        }
        publish_debug();
    }

  private:
    struct DebugPins {
        explicit DebugPins(hal::Instance* owner)
            : error_i{owner, "errorI"},
              error_d{owner, "errorD"},
              command_d{owner, "commandD"},
              command_dd{owner, "commandDD"},
              command_ddd{owner, "commandDDD"},
              ultimate_gain{owner, "ultimate-gain"},
              ultimate_period{owner, "ultimate-period"} {}
        hal::Out<double> error_i, error_d, command_d, command_dd, command_ddd;
        hal::Out<double> ultimate_gain, ultimate_period;
    };

    void calculate(hal::Period period) noexcept {
        const double period_s = static_cast<double>(period.ns) * 1e-9;
        const double per_second = 1.0 / period_s;
        const bool enabled = enable;
        const double cmd = command;
        const double fb = feedback;
        const bool index_now = index_enable;
        // An index reset just moved command and feedback by a whole position jump: skip the
        // difference-based terms for this one cycle.
        const bool index_reset = prev_index_enable_ && !index_now;

        double e = (!index_reset && error_previous_target) ? prev_cmd_ - fb : cmd - fb;
        error = e;

        if (tune_mode) {
            enter_tune_mode();
            return;
        }

        e = apply_deadband(clamp_symmetric(e, maxerror), deadband);

        if (enabled) {
            // Anti-windup: while the output is clamped, integrate only errors that pull back.
            if (e * limit_state_ <= 0.0) error_i_ += e * period_s;
            error_i_ = clamp_symmetric(error_i_, maxerror_i);
        } else {
            error_i_ = 0.0;
        }

        if (!index_reset) {
            command_deriv.set_own((cmd - prev_cmd_) * per_second);
            feedback_deriv.set_own((fb - prev_fb_) * per_second);
        }
        error_d_ = clamp_symmetric(command_deriv - feedback_deriv, maxerror_d);

        const double old_cmd_d = cmd_d_;
        cmd_d_ = clamp_symmetric(command_deriv, maxcmd_d);
        prev_index_enable_ = index_now;
        prev_cmd_ = cmd;
        prev_fb_ = fb;

        const double old_cmd_dd = cmd_dd_;
        cmd_dd_ = clamp_symmetric((cmd_d_ - old_cmd_d) * per_second, maxcmd_dd);
        cmd_ddd_ = clamp_symmetric((cmd_dd_ - old_cmd_dd) * per_second, maxcmd_ddd);

        double out = 0.0;
        if (enabled) {
            out = bias + pgain * e + igain * error_i_ + dgain * error_d_;
            out += cmd * ff0 + cmd_d_ * ff1 + cmd_dd_ * ff2 + cmd_ddd_ * ff3;
            const double limit = maxoutput;
            limit_state_ = 0.0;
            if (limit != 0.0) {
                if (out > limit) {
                    out = limit;
                    limit_state_ = 1.0;
                } else if (out < -limit) {
                    out = -limit;
                    limit_state_ = -1.0;
                }
            }
        } else {
            limit_state_ = 0.0;
        }
        output = out;
        publish_saturation(period);
    }

    void publish_saturation(hal::Period period) noexcept {
        if (limit_state_ != 0.0) {
            saturated_s_ += static_cast<double>(period.ns) * 1e-9;
            if (saturated_count_ != INT32_MAX) ++saturated_count_;
        } else {
            saturated_s_ = 0.0;
            saturated_count_ = 0;
        }
        saturated = limit_state_ != 0.0;
        saturated_s = saturated_s_;
        saturated_count = saturated_count_;
    }

    void enter_tune_mode() noexcept {
        // LinuxCNC also forgets the previous command here, so leaving tune mode starts with
        // one large command derivative; kept for identical behaviour.
        error_i_ = 0.0;
        error_d_ = 0.0;
        prev_cmd_ = 0.0;
        limit_state_ = 0.0;
        cmd_d_ = 0.0;
        cmd_dd_ = 0.0;
        output = 0.0;
        tune_ = TuneState::Idle;
    }

    void auto_tune(hal::Period period) noexcept {
        const double e = command - feedback;
        error = e;
        if (!enable || !tune_mode) tune_ = TuneState::Abort;
        const double effort = std::fabs(tune_effort.get());

        switch (tune_) {
            case TuneState::Idle:
                if (tune_start) tune_ = TuneState::Start;
                return;
            case TuneState::Start:
                tune_ = TuneState::Positive;
                cycle_count_ = 0;
                cycle_period_ns_ = 0;
                cycle_amplitude_ = 0.0;
                total_time_s_ = 0.0;
                avg_amplitude_ = 0.0;
                ultimate_gain_ = 0.0;
                ultimate_period_ = 0.0;
                output = bias + effort;
                return;
            case TuneState::Positive:
            case TuneState::Negative:
                if (relay_step(e, effort, period)) return;
                break;
            case TuneState::Pid:
            case TuneState::Abort:
                break;
        }
        // Finished or aborted: park the output at bias and wait for the next start.
        output = bias.get();
        tune_start = false;
        tune_ = tune_mode ? TuneState::Idle : TuneState::Pid;
    }

    // One period of the relay experiment; false once the last half cycle has ended.
    bool relay_step(double e, double effort, hal::Period period) noexcept {
        cycle_period_ns_ += period.ns;
        const bool below = e < 0.0;
        cycle_amplitude_ = std::fmax(cycle_amplitude_, std::fabs(e));
        if (below && tune_ == TuneState::Positive) {
            tune_ = TuneState::Negative;
            end_half_cycle();
        } else if (!below && tune_ == TuneState::Negative) {
            tune_ = TuneState::Positive;
            end_half_cycle();
        }
        output = below ? bias - effort : bias + effort;
        const std::uint32_t cycles = tune_cycles;
        if (cycles != 0 && cycle_count_ < cycles) return true;
        if (cycles != 0 && avg_amplitude_ > 0.0) set_tuned_gains(effort, cycles);
        return false;
    }

    void end_half_cycle() noexcept {
        const std::uint32_t cycles = tune_cycles;
        ++cycle_count_;
        if (cycles != 0) avg_amplitude_ += cycle_amplitude_ / cycles;
        cycle_amplitude_ = 0.0;
        total_time_s_ += static_cast<double>(cycle_period_ns_) * 1e-9;
        cycle_period_ns_ = 0;
    }

    void set_tuned_gains(double effort, std::uint32_t cycles) noexcept {
        ultimate_gain_ = 4.0 * effort / (std::numbers::pi * avg_amplitude_);
        ultimate_period_ = 2.0 * total_time_s_ / cycles;
        const double ku = ultimate_gain_;
        const double pu = ultimate_period_;
        ff0.set_own(0.0);
        ff2.set_own(0.0);
        if (tune_type == 0) {
            pgain.set_own(0.6 * ku);
            igain.set_own(1.2 * ku / pu);
            dgain.set_own(3.0 / 40.0 * ku * pu);
            ff1.set_own(0.0);
        } else {
            pgain.set_own(0.45 * ku);
            igain.set_own(0.54 * ku / pu);
            dgain.set_own(0.0);
            ff1.set_own(1.0);  // the output is then a velocity in user units per second
        }
    }

    void publish_debug() noexcept {
        if (!debug_) return;
        debug_->error_i = error_i_;
        debug_->error_d = error_d_;
        debug_->command_d = cmd_d_;
        debug_->command_dd = cmd_dd_;
        debug_->command_ddd = cmd_ddd_;
        debug_->ultimate_gain = ultimate_gain_;
        debug_->ultimate_period = ultimate_period_;
    }

    std::optional<DebugPins> debug_;
    double error_i_ = 0.0;
    double error_d_ = 0.0;
    double cmd_d_ = 0.0;
    double cmd_dd_ = 0.0;
    double cmd_ddd_ = 0.0;
    double prev_cmd_ = 0.0;
    double prev_fb_ = 0.0;
    double limit_state_ = 0.0;  // +1 / -1 while the output is clamped high / low
    bool prev_index_enable_ = false;
    double saturated_s_ = 0.0;
    std::int32_t saturated_count_ = 0;

    TuneState tune_ = TuneState::Pid;
    std::uint32_t cycle_count_ = 0;
    std::int64_t cycle_period_ns_ = 0;
    double cycle_amplitude_ = 0.0;
    double total_time_s_ = 0.0;
    double avg_amplitude_ = 0.0;
    double ultimate_gain_ = 0.0;
    double ultimate_period_ = 0.0;
};

}  // namespace

HAL_COMPONENT_WITH_OPTIONS(pid, Pid, "proportional/integral/derivative controller with auto tuning",
                           (hal::ComponentOptions{.default_count = 3}), "debug")
