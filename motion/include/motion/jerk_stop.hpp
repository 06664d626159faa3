// A jerk-limited stop along a path that lands on a given point: used by single block to stop at
// a block's end the plan runs through. From speed v0 and acceleration a0 (negative: slowing
// down) the stop takes three pieces at the jerk limit j:
//
//   accel ^
//      a0 +--.                             1: jerk -j (or +j) until the deceleration is d
//         |   \                2           2: deceleration d (may be empty)
//       0 +----\----------------------.    3: jerk +j back to 0, reaching speed 0 with it
//         |     \________________/
//      -d +
//
// For a peak d the distance is S(d); a larger d stops sooner. decel_for() finds the d whose stop
// is exactly as long as the distance left, so re-solving every period lands on the point.
// Pure maths, realtime-safe (noexcept, bounded time).
#pragma once

#include <optional>

namespace motion {

struct JerkStopState {
    double v_mm_s = 0;   // path speed (>= 0)
    double a_mm_s2 = 0;  // path acceleration
};

// The deceleration peak above which piece 2 would be empty (the stop is the shortest then).
double jerk_stop_max_peak(const JerkStopState& s, double jerk_mm_s3) noexcept;
// Distance to rest with peak deceleration decel (clamped to jerk_stop_max_peak).
double jerk_stop_distance(const JerkStopState& s, double decel_mm_s2, double jerk_mm_s3) noexcept;
// The peak deceleration <= max_decel whose stop is exactly distance_mm long; nullopt when even
// max_decel (or the shortest stop) needs more room.
std::optional<double> jerk_stop_decel_for(const JerkStopState& s, double distance_mm,
                                          double max_decel_mm_s2, double jerk_mm_s3) noexcept;

struct JerkStopStep {
    JerkStopState next;
    double ds_mm = 0;
    double jerk_mm_s3 = 0;  // the jerk at the end of the step
    bool at_rest = false;   // the stop ended within the step
};
// Follows the stop with peak decel for dt.
JerkStopStep jerk_stop_step(const JerkStopState& s, double decel_mm_s2, double jerk_mm_s3,
                            double dt_s) noexcept;

}  // namespace motion
