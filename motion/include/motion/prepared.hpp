// The fixed-size record the planner hands to the realtime side, and how to sample it.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

#include "motion/geometry.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace motion {

struct PreparedSegment {
    Element geom;
    Profile1D profile;  // s(t) over [0, profile.duration_s]
    // How much faster than planned time may run (feed override > 100 %) in each profile phase.
    std::array<double, kMaxPhases> phase_rate_cap{};
    std::int32_t line = 0;     // source line tag
    std::uint32_t seq = 0;     // running number, for diagnostics
    bool rapid = false;        // a traverse (G0): the rapid override applies, not the feed override
    bool program_end = false;  // the last record before the planner was told finish(): ends at rest
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

}  // namespace motion
