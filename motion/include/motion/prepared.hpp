// The fixed-size record the planner hands to the realtime side, and how to sample it.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "motion/geometry.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace motion {

// What a non-motion record asks of the machine. The sampler stands still on such a record (the
// motion before it has ended at rest) until its owner reports the action carried out, so an
// action happens exactly between the motion before it and the motion after it in program order.
enum class ActionKind : std::uint8_t {
    None,           // an ordinary motion (or dwell) record
    SpindleSpeed,   // number = rpm (>= 0)
    Spindle,        // value = 0 stop, 1 forward (M03), -1 reverse (M04)
    SpindleOrient,  // number = angle in degrees
    Coolant,        // flag = flood on (M08) / everything off (M09)
    ToolChange,     // value = tool number: prepare, then change
    SetToolNumber,  // value = tool number (M903): no handshake
    SetOutput,      // value = digital output index, flag = level
    WaitInput,      // value = digital input index, flag = level, number = timeout in s
    Pause,          // M00
    OptionalPause,  // M01: pauses only while the optional-stop switch is on
    ToolOffset,     // number = tool length offset in Z, mm (G43/G49): motion.tooloffset.z

    // Before the first feed move after a spindle start or speed change: spindle.0.at-speed.
    SpindleAtSpeed,
    // G904: the sampler runs PreparedSegment::probe; flag = feed override fixed at 100 % (G903).
    ConditionalMove,
    Message,       // value = number of the M801 message reached (see PreparedSegment::message)
    MaskLimits,    // flag = limit switches masked (M802 P131072) / obeyed again (P131073)
    HomeDone,      // M902: value = axis, number = its machine coordinate from here on, mm
    SpindleClamp,  // flag = clamped (V5.4 M10) / released (M11)
};

struct Action {
    ActionKind kind = ActionKind::None;
    bool flag = false;
    std::int32_t value = 0;
    double number = 0;
};

// One axis of a conditional move (G904, probe_jog.hpp). Axes X Y Z only.
inline constexpr int kProbeAxes = 3;
struct ProbeAxis {
    std::int32_t input = -1;  // motion.digital-in index; < 0: the axis does not take part
    bool level = false;       // the input level that stops the axis
    double speed_mm_s = 0;    // signed: the direction of travel
    double travel_mm = 0;     // farthest it may go (the maximum travel or the soft limit)
};

struct PreparedSegment {
    Element geom;
    Profile1D profile;  // s(t) over [0, profile.duration_s]
    // How much faster than planned time may run (feed override > 100 %) in each profile phase.
    std::array<double, kMaxPhases> phase_rate_cap{};
    std::int32_t line = 0;     // source line tag
    std::uint32_t seq = 0;     // running number, for diagnostics
    bool rapid = false;        // a traverse (G0): the rapid override applies, not the feed override
    bool program_end = false;  // the last record before the planner was told finish(): ends at rest
    // Next to a junction that is not smooth (planner.hpp): the plan keeps junction_share of the
    // acceleration and jerk for the step there, which the time scale r multiplies (by r for a
    // velocity step, r^2 for a curvature step); the sampler keeps that share out of its room.
    bool rough = false;
    Action action;             // kind != None: a standing record of zero duration (see Action)
    // Digital outputs synchronised with motion (M901; LinuxCNC's M62/M63): bit n set/cleared
    // changes motion.digital-out-n in the period the sampler starts following this record.
    std::uint64_t dout_set = 0;
    std::uint64_t dout_clear = 0;
    // > 0: the program's M801 messages up to this number have been reached when the sampler
    // starts following this record (like the outputs: shown without stopping the path).
    std::uint32_t message = 0;
    // The planner copies PathSegment::move_id to every record made from that segment (the
    // blend into it included), so the feeder can find where a move begins.
    std::uint32_t move_id = 0;
    std::array<ProbeAxis, kProbeAxes> probe{};  // ActionKind::ConditionalMove only
};
static_assert(std::is_trivially_copyable_v<PreparedSegment>,
              "PreparedSegment must be copyable through a lock-free ring");

struct MotionSample {
    AxisArray pos_mm{};
    AxisArray vel_mm_s{};
    AxisArray acc_mm_s2{};
    AxisArray jerk_mm_s3{};
    std::int32_t line = 0;
};

// Samples one record at local time t_s (clamped to its duration), at planned speed.
// Realtime-safe: noexcept, no allocation, bounded time.
MotionSample sample(const PreparedSegment& seg, double t_s) noexcept;

// A standing record that asks for `action` at pos_mm, tagged with the source line.
PreparedSegment action_record(const AxisArray& pos_mm, const Action& action,
                              std::int32_t line) noexcept;

}  // namespace motion
