#include "motion/probe_jog.hpp"

#include <algorithm>
#include <cmath>

#include "motion/limits.hpp"

namespace motion {

void ProbeJog::start(const AxisArray& from_mm, const std::array<ProbeAxis, kProbeAxes>& axes,
                     const AxisLimits& limits) noexcept {
    pos_mm_ = from_mm;
    vel_mm_s_ = {};
    stopping_ = false;
    active_ = true;
    for (int k = 0; k < kProbeAxes; ++k) {
        Axis& ax = axes_[k];
        ax.cfg = axes[k];
        ax.start_mm = from_mm[k];
        ax.acc_mm_s2 = limits.acc_mm_s2[k];
        ax.vmax_mm_s = limits.vel_mm_s[k];
        ax.state = ax.cfg.input >= 0 && ax.cfg.speed_mm_s != 0 ? State::Running : State::Off;
        ax.landing = false;
    }
    // A linear kinematics' joints (CoreXY: X and Y at once ask X + Y of motor A): the moving
    // axes get the share of their limits that keeps every joint within its own.
    std::array<bool, kAxes> moving{};
    for (int k = 0; k < kProbeAxes; ++k) moving[k] = axes_[k].state == State::Running;
    const IndependentShares share = independent_axes_shares(limits, moving);
    for (Axis& ax : axes_) {
        ax.acc_mm_s2 *= share.acc;
        ax.vmax_mm_s *= share.vel;
    }
}

bool ProbeJog::finished() const noexcept {
    return active_ && std::none_of(axes_.begin(), axes_.end(), [](const Axis& ax) {
               return ax.state == State::Running || ax.state == State::Braking;
           });
}

AxisArray ProbeJog::trip_mm() const noexcept {
    AxisArray out = pos_mm_;
    for (int k = 0; k < kProbeAxes; ++k)
        if (axes_[k].state == State::Tripped || (axes_[k].state == State::Braking && !stopping_))
            out[k] = axes_[k].trip_mm;
    return out;
}

bool ProbeJog::tripped() const noexcept {
    bool any = false;
    for (const Axis& ax : axes_) {
        if (ax.state == State::Off) continue;
        if (ax.state != State::Tripped) return false;
        any = true;
    }
    return any;
}

void ProbeJog::step(double dt, std::uint64_t inputs, double speed_scale) noexcept {
    for (int k = 0; k < kProbeAxes; ++k) {
        const int in = axes_[k].cfg.input;
        const bool at_level = in >= 0 && in < 64 && ((inputs >> in) & 1) == axes_[k].cfg.level;
        step_axis(k, dt, at_level, speed_scale);
    }
}

// Works along the axis's direction of travel: u = distance gone, w = speed (never negative, the
// axis never turns back). Speed changes by at most a dt per period. Before the next period's
// speed w' would need more than the full deceleration a to stop by the farthest point
// (left - (w + w') dt / 2 < w'^2 / 2a), the axis starts landing: it brakes at the constant
// d = w^2 / 2 left, which is <= a at that moment and stops exactly on the point. A tripped or
// stopped axis brakes at a (at d if that were larger: it never overshoots either).
void ProbeJog::step_axis(int k, double dt, bool at_level, double scale) noexcept {
    Axis& ax = axes_[k];
    if (ax.state != State::Running && ax.state != State::Braking) {
        vel_mm_s_[k] = 0;
        return;
    }
    if (ax.state == State::Running && (stopping_ || at_level)) {
        ax.state = State::Braking;
        ax.trip_mm = pos_mm_[k];  // not yet stepped: last period's command
    }
    const double dir = ax.cfg.speed_mm_s > 0 ? 1.0 : -1.0;
    const double a = ax.acc_mm_s2;
    const double travel = ax.cfg.travel_mm;
    const double u = dir * (pos_mm_[k] - ax.start_mm);
    const double w = dir * vel_mm_s_[k];
    const double left = std::max(0.0, travel - u);
    double decel = 0;  // > 0: braking at this constant rate
    if (ax.state == State::Braking) {
        decel = left > 0 ? std::max(a, w * w / (2 * left)) : a;
    } else {
        const double target =
            std::min(std::fabs(ax.cfg.speed_mm_s) * std::max(scale, 0.0), ax.vmax_mm_s);
        const double w_next = std::clamp(target, std::max(0.0, w - a * dt), w + a * dt);
        if (!ax.landing && left - (w + w_next) / 2 * dt < w_next * w_next / (2 * a))
            ax.landing = true;
        if (!ax.landing) {
            pos_mm_[k] = ax.start_mm + dir * (u + (w + w_next) / 2 * dt);
            vel_mm_s_[k] = dir * w_next;
            return;
        }
        if (left <= 0 || w <= 0) {  // on the point (a travel of 0, or landed)
            pos_mm_[k] = ax.start_mm + dir * travel;
            vel_mm_s_[k] = 0;
            ax.state = State::AtLimit;
            return;
        }
        decel = w * w / (2 * left);
    }
    double u1 = 0, w1 = 0;
    if (w <= decel * dt) {  // at rest within this period
        u1 = u + w * w / (2 * decel);
        if (ax.state == State::Running) u1 = travel;  // exactly, whatever the rounding
    } else {
        w1 = w - decel * dt;
        u1 = u + (w + w1) / 2 * dt;
    }
    u1 = std::min(u1, travel);
    pos_mm_[k] = ax.start_mm + dir * u1;
    vel_mm_s_[k] = dir * w1;
    if (w1 > 0) return;
    if (ax.state == State::Running)
        ax.state = State::AtLimit;
    else
        ax.state = stopping_ ? State::Stopped : State::Tripped;
}

}  // namespace motion
