// The realtime half of a conditional move (NcStudio G904, the machine's probing and tool-setting
// move): each taking part axis runs on its own at its signed speed until its input reaches the
// level asked for, then brakes at its full acceleration limit; an axis whose input never comes
// stops exactly at its farthest allowed point (the programmed maximum travel or the soft limit).
//
//   speed ^      input seen
//         |    ______|
//         |   /      \          ramps at the axis's acceleration limit (jerk ignored, like
//         |  /        \         the fault stop): from v it stops within v^2 / 2a plus one
//         | /          \        period of travel
//         +--------------> t
//
// Hold, abort and the feed override act through speed_scale; stop_now() brakes every axis
// (abort, fault). Realtime-safe: noexcept, no allocation, bounded time.
#pragma once

#include <array>
#include <cstdint>

#include "motion/prepared.hpp"
#include "motion/types.hpp"

namespace motion {

class ProbeJog {
  public:
    void start(const AxisArray& from_mm, const std::array<ProbeAxis, kProbeAxes>& axes,
               const AxisLimits& limits) noexcept;
    // One period: `inputs` bit n = motion.digital-in-n now; speed_scale in [0, max rate]
    // (0 = held). Updates pos_mm() and vel_mm_s().
    void step(double dt_s, std::uint64_t inputs, double speed_scale) noexcept;
    // Every axis brakes to rest and stops there (abort, fault); nothing trips after this.
    void stop_now() noexcept { stopping_ = true; }

    bool active() const noexcept { return active_; }
    bool finished() const noexcept;  // started, and every axis at rest for good
    // Every taking-part axis stopped because its input reached the level.
    bool tripped() const noexcept;
    const AxisArray& pos_mm() const noexcept { return pos_mm_; }
    // Where each axis was when its input came: the position commanded in the period before the
    // one that saw the input at its level (the input a period reads answers the command of the
    // period before). An axis that did not trip gives where it stopped; axes that do not take
    // part, where they stand.
    AxisArray trip_mm() const noexcept;
    const AxisArray& vel_mm_s() const noexcept { return vel_mm_s_; }
    void clear() noexcept { active_ = false; }

  private:
    enum class State : std::uint8_t { Off, Running, Braking, Tripped, AtLimit, Stopped };
    struct Axis {
        ProbeAxis cfg;
        State state = State::Off;
        double start_mm = 0;
        double acc_mm_s2 = 0;
        double vmax_mm_s = 0;
        bool landing = false;  // braking onto the farthest point
        double trip_mm = 0;    // latched when the input came (State::Braking from Running)
    };
    void step_axis(int k, double dt, bool input_at_level, double scale) noexcept;

    std::array<Axis, kProbeAxes> axes_{};
    AxisArray pos_mm_{};
    AxisArray vel_mm_s_{};
    bool active_ = false;
    bool stopping_ = false;
};

}  // namespace motion
