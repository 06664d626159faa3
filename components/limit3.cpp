// limit3: makes the output follow the input while keeping position within [min, max],
// velocity within maxv and acceleration within maxa, LinuxCNC-compatible (`loadrt limit3`).
//
// Each cycle it looks one period ahead:
//   1. From the output's current velocity, the reachable positions next cycle are
//      [out + v_lo*T, out + v_hi*T] with v_lo/v_hi the slowest/fastest velocity maxa allows.
//   2. For both extremes it predicts where a full-acceleration stop would end, and where the
//      output and the (linearly extrapolated) input would be once their velocities match.
//   3. The goal is a position limit when a stop would overshoot it (or when the input sits
//      beyond it and the output can still wait), otherwise the input itself.
//   4. It then jumps onto the goal when reachable this cycle, accelerates fully towards it
//      when no overshoot is possible, lands smoothly with a uniform acceleration spread over
//      up to smooth-steps periods when close, and brakes fully when it would overshoot.
// The sequence of decisions is LinuxCNC's, so outputs agree cycle for cycle.
#include <cmath>

#include "hal/component.hpp"

namespace {

// Guards against division round-off when comparing predicted positions.
constexpr double kEpsilon = 1e-9;

struct Limit3 : hal::Instance {
    hal::In<double> in{this, "in"};
    hal::In<bool> enable{this, "enable", true};
    hal::Out<double> out{this, "out"};
    hal::In<bool> load{this, "load", false};
    hal::In<double> min{this, "min", -1e20};
    hal::In<double> max{this, "max", 1e20};
    hal::In<double> maxv{this, "maxv", 1e20};
    hal::In<double> maxa{this, "maxa", 1e20};
    hal::In<std::uint32_t> smooth_steps{this, "smooth-steps", 2u};

    void update(hal::Period period) noexcept;

  private:
    // Commits the output for this cycle and remembers the input it was computed from.
    void commit(double next_out, double input) noexcept {
        out_prev_ = out_now_;
        out_now_ = next_out;
        in_prev_ = input;
        out = next_out;
    }

    double in_prev_ = 0.0;
    double out_prev_ = 0.0;
    double out_now_ = 0.0;
};

// Distance covered while the velocity changes linearly from v_from to v_to over t seconds.
double ramp_distance(double v_from, double v_to, double t) noexcept {
    return (v_to + v_from) / 2 * t;
}

void Limit3::update(hal::Period period) noexcept {
    const double T = period.s;
    const double input = enable ? in.get() : 0.0;  // disabled: return to 0 within the limits
    const double lo_limit = min, hi_limit = max, v_limit = maxv, a_limit = maxa;

    if (load) {
        const double clamped = std::fmin(hi_limit, std::fmax(lo_limit, input));
        commit(clamped, clamped);
        return;
    }

    const double out_pos = out_now_;
    const double in_vel = (input - in_prev_) / T;
    const double out_vel = (out_pos - out_prev_) / T;

    // 1. Reachable velocities and positions next cycle.
    const double v_lo = std::fmax(out_vel - a_limit * T, -v_limit);
    const double v_hi = std::fmin(out_vel + a_limit * T, v_limit);
    const double reach_lo = out_pos + v_lo * T;
    const double reach_hi = out_pos + v_hi * T;
    auto reachable = [&](double p) { return p <= reach_hi && p >= reach_lo; };

    // 2. Stop positions (stopping starts from the previous period, hence + T) ...
    const double stop_hi = out_pos + ramp_distance(v_hi, 0.0, std::fabs(-v_hi / a_limit) + T);
    const double stop_lo = out_pos + ramp_distance(v_lo, 0.0, std::fabs(-v_lo / a_limit) + T);
    // ... and positions once the output matches the input's velocity (it runs one period
    // behind the input, hence - T).
    const double match_t_hi = std::fabs((in_vel - v_hi) / a_limit) - T;
    const double match_t_lo = std::fabs((in_vel - v_lo) / a_limit) - T;
    const double out_match_hi = reach_hi + ramp_distance(v_hi, in_vel, match_t_hi);
    const double out_match_lo = reach_lo + ramp_distance(v_lo, in_vel, match_t_lo);
    const double in_match_hi = input + in_vel * match_t_hi;
    const double in_match_lo = input + in_vel * match_t_lo;

    // 3. Choose the goal; by default it is a stop at a position limit.
    double goal_lo, goal_hi, goal_now, goal_prev;
    double vel_diff = -out_vel;
    double achieve_lo = stop_lo, achieve_hi = stop_hi;
    auto aim_at_limit = [&](double limit) { goal_lo = goal_hi = goal_now = goal_prev = limit; };
    if (stop_hi > hi_limit + kEpsilon && !reachable(hi_limit)) {
        aim_at_limit(hi_limit);
    } else if (stop_lo < lo_limit - kEpsilon && !reachable(lo_limit)) {
        aim_at_limit(lo_limit);
    } else if (input >= hi_limit && in_match_hi > out_match_hi) {
        aim_at_limit(hi_limit);
    } else if (input <= lo_limit && in_match_lo < out_match_lo) {
        aim_at_limit(lo_limit);
    } else {
        goal_lo = in_match_lo;
        goal_hi = in_match_hi;
        goal_now = input;
        goal_prev = in_prev_;
        vel_diff = out_vel - in_vel;
        achieve_lo = out_match_lo;
        achieve_hi = out_match_hi;
    }

    // 4. Act. t is the time to close the position gap at the average velocity difference.
    const double pos_diff = out_pos - goal_prev;
    const double t = std::fabs(vel_diff) < kEpsilon ? 0.0 : pos_diff / (vel_diff / 2);

    if (reachable(goal_now) && std::fabs(t) <= T) return commit(goal_now, input);
    if (achieve_hi < goal_hi + kEpsilon) return commit(reach_hi, input);  // cannot overshoot
    if (achieve_lo > goal_lo - kEpsilon) return commit(reach_lo, input);

    // Close to the goal: always braking at full rate would oscillate around it, so spread a
    // uniform acceleration over a whole number of periods.
    if (std::fabs(t) < T * smooth_steps) {
        const double sign = t >= 0 ? 1.0 : -1.0;
        const double whole_periods_t = static_cast<int>((t - kEpsilon * sign) / T + sign) * T;
        const double accel = vel_diff / whole_periods_t;
        const double step = (out_vel + accel * T) * T;
        return commit(std::fmin(reach_hi, std::fmax(reach_lo, out_pos + step)), input);
    }

    if (goal_hi + kEpsilon < achieve_hi && goal_prev > out_pos) return commit(reach_lo, input);
    if (goal_lo - kEpsilon > achieve_lo && goal_prev < out_pos) return commit(reach_hi, input);
    commit((reach_lo + reach_hi) / 2, input);  // not expected to be reached: coast
}

}  // namespace

HAL_COMPONENT(limit3, Limit3, "Follow input signal while obeying limits")
