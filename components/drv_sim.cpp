// drv_sim: a simulated servo axis — the drive, the motor and its encoder, plus home and limit
// switches — so a machine config runs with no hardware (`loadrt drv_sim [count=N | names=…]
// [mode=velocity|torque|ideal,…]`).
//
// Each cycle, in order:
//   1. fault: latched by fault-inject, by |velocity| > max-vel (when max-vel > 0), by a
//      non-physical parameter (inertia <= 0 in torque mode) or by a command that is not a
//      finite number while enabled (a NaN must not reach the motor model, where it would stick
//      forever); cleared while enable is FALSE and fault-inject is FALSE (the usual "toggle
//      amp-enable to reset" of real drives).
//   2. motion, only while enable is TRUE and there is no fault (otherwise the holding brake
//      stops the motor at once: velocity 0, position held):
//        ideal     pos += (pos-cmd - pos) * (1 - exp(-dt / lag)), pos = pos-cmd when lag = 0
//                  (the exact step response of a first-order lag, so the result does not
//                  depend on the thread period)
//        velocity  the drive's own velocity loop is a first-order lag of time constant vel-tc:
//                  vel += (vel-cmd - vel) * (1 - exp(-dt / vel-tc)), vel = vel-cmd when 0;
//                  then pos += vel * dt
//        torque    rigid motor and load: acc = (torque-cmd - damping * vel) / inertia,
//                  vel += acc * dt, pos += vel * dt (semi-implicit Euler: it keeps the
//                  energy of an undamped motor under a P loop bounded, where explicit Euler
//                  would let it grow; damping * dt / inertia must stay below 1)
//   3. encoder: counts = round(pos * scale) - round(zero * scale), pos-fb = counts / scale;
//      scale = 0 turns the quantisation off (pos-fb = pos - zero, counts = 0). zero starts at 0.
//      Index marks sit every index-spacing units from index-offset (none when spacing is 0);
//      `index` is TRUE in a cycle that crossed one. With index-enable TRUE, the first mark
//      crossed becomes the new zero and index-enable is cleared, as LinuxCNC's encoder does on
//      phase Z (the motion controller's homing to index relies on that handshake).
//   4. switches from the true position, each with hysteresis switch-hyst (a switch that is on
//      turns off only once the position is hyst back inside):
//        home-sw     pos in [home-sw-min, home-sw-max]
//        pos-lim-sw  pos >= pos-lim-pos
//        neg-lim-sw  pos <= neg-lim-pos
//      The defaults (±inf) never switch.
// The motor starts at rest at start-pos (placed there when its thread first starts).
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "hal/component.hpp"

namespace {

enum class Mode { Velocity, Torque, Ideal };

// Why the drive faulted, published in the fault-code param so a test or a UI can tell.
enum FaultCode : std::uint32_t {
    kNoFault = 0,
    kInjected = 1,
    kOverspeed = 2,
    kBadParams = 3,
    kBadCommand = 4,
};

Mode parse_mode(const std::string& text) {
    if (text == "velocity") return Mode::Velocity;
    if (text == "torque") return Mode::Torque;
    if (text == "ideal") return Mode::Ideal;
    throw hal::Error("mode=" + text + " is not one of velocity, torque, ideal");
}

// One side of a switch with hysteresis: on at `edge`, off again only `hyst` back inside.
// `above`: the switch is on beyond the edge in the positive direction.
bool switch_state(bool was_on, double pos, double edge, double hyst, bool above) noexcept {
    const double release = above ? edge - hyst : edge + hyst;
    if (above) return was_on ? pos >= release : pos >= edge;
    return was_on ? pos <= release : pos <= edge;
}

// Fraction of the remaining distance a first-order lag of time constant tau_s covers in dt_s.
double lag_fraction(double dt_s, double tau_s) noexcept {
    return tau_s > 0.0 ? 1.0 - std::exp(-dt_s / tau_s) : 1.0;
}

struct DrvSim : hal::Instance {
    static constexpr double kInf = std::numeric_limits<double>::infinity();

    hal::In<bool> enable{this, "enable"};
    hal::In<bool> fault_inject{this, "fault-inject"};
    hal::IO<bool> index_enable{this, "index-enable"};
    hal::In<double> pos_cmd{this, "pos-cmd"};
    hal::In<double> vel_cmd{this, "vel-cmd"};
    hal::In<double> torque_cmd{this, "torque-cmd"};

    hal::Out<double> pos_fb{this, "pos-fb"};
    hal::Out<double> vel_fb{this, "vel-fb"};
    hal::Out<double> motor_pos{this, "motor-pos"};
    hal::Out<std::int32_t> counts{this, "counts"};
    hal::Out<bool> index{this, "index"};
    hal::Out<bool> home_sw{this, "home-sw"};
    hal::Out<bool> pos_lim_sw{this, "pos-lim-sw"};
    hal::Out<bool> neg_lim_sw{this, "neg-lim-sw"};
    hal::Out<bool> fault{this, "fault"};

    hal::Param<double> scale{this, "scale", 1000.0};
    hal::Param<double> lag{this, "lag", 0.0};
    hal::Param<double> vel_tc{this, "vel-tc", 0.0};
    hal::Param<double> inertia{this, "inertia", 1.0};
    hal::Param<double> damping{this, "damping", 0.0};
    hal::Param<double> max_vel{this, "max-vel", 0.0};
    hal::Param<double> home_sw_min{this, "home-sw-min", kInf};
    hal::Param<double> home_sw_max{this, "home-sw-max", kInf};
    hal::Param<double> pos_lim_pos{this, "pos-lim-pos", kInf};
    hal::Param<double> neg_lim_pos{this, "neg-lim-pos", -kInf};
    hal::Param<double> switch_hyst{this, "switch-hyst", 0.0};
    hal::Param<double> index_spacing{this, "index-spacing", 0.0};
    hal::Param<double> index_offset{this, "index-offset", 0.0};
    hal::Param<double> start_pos{this, "start-pos", 0.0};
    hal::Param<std::uint32_t> fault_code{this, "fault-code", 0, hal::ParamDir::RO};

    Mode mode_ = parse_mode(arg("mode").value_or("velocity"));
    double pos_ = 0.0;
    double vel_ = 0.0;
    double zero_ = 0.0;  // true position that the encoder reads as 0 (moved by an index reset)
    bool home_on_ = false;
    bool pos_lim_on_ = false;
    bool neg_lim_on_ = false;
    std::uint32_t fault_ = kNoFault;
    bool started_ = false;

    // The motor is placed at start-pos when its thread first starts (a config may set the param
    // after loadrt, so the constructor is too early); a later stop/start keeps the position.
    void start() override {
        if (started_) return;
        started_ = true;
        pos_ = start_pos;
        vel_ = 0.0;
        publish();
    }

    void update(hal::Period p) noexcept {
        update_fault();
        const double old_pos = pos_;
        if (enable && fault_ == kNoFault) {
            move(p.s);
        } else {
            vel_ = 0.0;
        }
        if (mode_ == Mode::Ideal) vel_ = p.s > 0.0 ? (pos_ - old_pos) / p.s : 0.0;
        if (max_vel > 0.0 && std::fabs(vel_) > max_vel && fault_ == kNoFault) fault_ = kOverspeed;
        update_index(old_pos);
        publish();
    }

    // The first index mark crossed on the way from old_pos to pos_ (a fast motor may pass
    // several in one period; hardware latches the first).
    void update_index(double old_pos) noexcept {
        const double spacing = index_spacing;
        bool crossed = false;
        if (spacing > 0.0) {
            const double offset = index_offset;
            const double k_old = std::floor((old_pos - offset) / spacing);
            const double k_new = std::floor((pos_ - offset) / spacing);
            if (k_new != k_old) {
                crossed = true;
                const double mark = offset + spacing * (k_new > k_old ? k_old + 1.0 : k_old);
                if (index_enable) {
                    zero_ = mark;
                    index_enable = false;
                }
            }
        }
        index = crossed;
    }

    void update_fault() noexcept {
        if (fault_inject) {
            if (fault_ == kNoFault) fault_ = kInjected;
        } else if (!enable) {
            fault_ = kNoFault;
        }
        if (mode_ == Mode::Torque && !(inertia > 0.0) && fault_ == kNoFault) fault_ = kBadParams;
        if (enable && !std::isfinite(active_command()) && fault_ == kNoFault) fault_ = kBadCommand;
    }

    double active_command() const noexcept {
        switch (mode_) {
            case Mode::Ideal:
                return pos_cmd;
            case Mode::Velocity:
                return vel_cmd;
            case Mode::Torque:
                return torque_cmd;
        }
        return 0.0;
    }

    void move(double dt_s) noexcept {
        switch (mode_) {
            case Mode::Ideal:
                pos_ += (pos_cmd - pos_) * lag_fraction(dt_s, lag);
                break;
            case Mode::Velocity:
                vel_ += (vel_cmd - vel_) * lag_fraction(dt_s, vel_tc);
                pos_ += vel_ * dt_s;
                break;
            case Mode::Torque:
                vel_ += (torque_cmd - damping * vel_) / inertia * dt_s;
                pos_ += vel_ * dt_s;
                break;
        }
    }

    void publish() noexcept {
        const double s = scale;
        if (s != 0.0) {
            const auto n = static_cast<std::int64_t>(std::llround(pos_ * s)) -
                           static_cast<std::int64_t>(std::llround(zero_ * s));
            counts =
                static_cast<std::int32_t>(static_cast<std::uint32_t>(n));  // wraps like a counter
            pos_fb = static_cast<double>(n) / s;
        } else {
            counts = 0;
            pos_fb = pos_ - zero_;
        }
        vel_fb = vel_;
        motor_pos = pos_;
        const double hyst = switch_hyst;
        home_on_ = switch_state(home_on_, pos_, home_sw_min, hyst, true) &&
                   switch_state(home_on_, pos_, home_sw_max, hyst, false);
        pos_lim_on_ = switch_state(pos_lim_on_, pos_, pos_lim_pos, hyst, true);
        neg_lim_on_ = switch_state(neg_lim_on_, pos_, neg_lim_pos, hyst, false);
        home_sw = home_on_;
        pos_lim_sw = pos_lim_on_;
        neg_lim_sw = neg_lim_on_;
        fault = fault_ != kNoFault;
        fault_code = fault_;
    }
};

}  // namespace

HAL_COMPONENT(drv_sim, DrvSim, "Simulated servo axis: motor, encoder, home and limit switches",
              "mode")
