// One-dimensional velocity profiles along a path parameter s (mm): trapezoids when the jerk is
// unlimited, seven-phase S-curves when it is limited. Every profile here starts and ends with
// zero acceleration when jerk-limited, so consecutive elements join without an acceleration step.
//
//   v ^        ____________ vpeak
//     |      /              \          jerk-limited: each ramp is  +J, (0), -J
//     |  ___/                \___      unlimited:    each ramp is  constant +-A
//     | v_in                    v_out
//     +-----------------------------> t
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace motion {

// A polynomial piece of s(t): from time t0_s the state is (s0, v0, a0) and the jerk is j.
struct ProfilePhase {
    double t0_s = 0;
    double s0_mm = 0;
    double v0_mm_s = 0;
    double a0_mm_s2 = 0;
    double j_mm_s3 = 0;
};

struct PathState {
    double s_mm = 0;
    double v_mm_s = 0;
    double a_mm_s2 = 0;
    double j_mm_s3 = 0;
};

inline constexpr int kMaxPhases = 7;

struct Profile1D {
    std::array<ProfilePhase, kMaxPhases> phases{};
    std::uint8_t count = 0;
    double duration_s = 0;
    double peak_v_mm_s = 0;
    double peak_a_mm_s2 = 0;  // largest |acceleration| the profile uses
    double peak_j_mm_s3 = 0;  // largest |jerk| the profile uses (0 for trapezoids)

    // State at time t (clamped to [0, duration]); noexcept, no allocation, at most 7 steps.
    PathState at(double t_s) const noexcept;
};

// Limits along the path for one element. jerk 0 = unlimited.
struct TangentLimits {
    double acc_mm_s2 = 0;
    double jerk_mm_s3 = 0;
};

// Time to change speed by dv >= 0 starting and ending at zero acceleration.
double ramp_time_s(double dv_mm_s, const TangentLimits& lim) noexcept;
// Distance covered by that ramp between speeds v0 and v1 (symmetric in v0, v1).
double ramp_distance_mm(double v0_mm_s, double v1_mm_s, const TangentLimits& lim) noexcept;

namespace detail {
// reachable_speed_mm_s() for length_mm > 0 and lim.jerk_mm_s3 > 0.
double reachable_speed_jerk_limited_mm_s(double v0_mm_s, double length_mm,
                                         const TangentLimits& lim) noexcept;
}  // namespace detail

// Largest speed reachable (or from which v0 is reachable, by symmetry) within length_mm.
// Inline without a jerk limit: the planner asks for it twice per element in every look-ahead
// pass, and the call cost more than the root.
inline double reachable_speed_mm_s(double v0_mm_s, double length_mm,
                                   const TangentLimits& lim) noexcept {
    if (length_mm <= 0) return v0_mm_s;
    if (!(lim.jerk_mm_s3 > 0)) return std::sqrt(v0_mm_s * v0_mm_s + 2 * lim.acc_mm_s2 * length_mm);
    return detail::reachable_speed_jerk_limited_mm_s(v0_mm_s, length_mm, lim);
}

// The fastest profile over length_mm from v_in to v_out not exceeding vcap. The caller
// guarantees ramp_distance_mm(v_in, v_out) <= length_mm (up to rounding).
Profile1D build_profile(double length_mm, double v_in_mm_s, double v_out_mm_s, double vcap_mm_s,
                        const TangentLimits& lim) noexcept;
// The same, written into `out`, which must be a default Profile1D (the planner builds it in the
// record it emits).
void build_profile_into(Profile1D& out, double length_mm, double v_in_mm_s, double v_out_mm_s,
                        double vcap_mm_s, const TangentLimits& lim) noexcept;

}  // namespace motion
