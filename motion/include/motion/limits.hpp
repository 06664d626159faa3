// Turns per-axis machine limits into limits along one path element.
//
// For a curve p(s) traversed with path-parameter speed v = ds/dt, tangential acceleration a and
// jerk j, axis k sees
//     velocity      v p'_k
//     acceleration  a p'_k + v^2 p''_k
//     jerk          j p'_k + 3 v a p''_k + v^3 p'''_k
// With the per-axis bounds g1, g2, g3 of |p'|, |p''|, |p'''| (geometry.hpp) the element gets a
// speed cap, a tangential acceleration and a tangential jerk such that every axis stays within
// its share of the machine limits for every speed up to the cap.
#pragma once

#include "motion/geometry.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace motion {

// Fractions of the machine limits an element may use.
struct LimitShares {
    double acc = 1;   // of acc_mm_s2
    double jerk = 1;  // of jerk_mm_s3
    // Share of that acceleration a corner blend may spend turning, the rest being left for
    // speed changes inside it; 0 = the default (0.95). Arcs and lines ignore it.
    double blend_centripetal = 0;
};

struct ElementLimits {
    double vcap_mm_s = 0;
    TangentLimits tangent;
};

// feed_mm_s <= 0 means "no feed limit" (rapid).
ElementLimits element_limits(const Element& e, const ElementBounds& b, const AxisLimits& lim,
                             double feed_mm_s, const LimitShares& share) noexcept;

// Shortest cut l (mm) of a parabolic corner blend (make_parabola: second derivative
// dt_turn / 2l, dt_turn = T2 - T1) whose speed cap under these shares is at least v_mm_s,
// ignoring jerk limits.
double parabola_cut_for_speed_mm(const AxisArray& dt_turn, double v_mm_s, const AxisLimits& lim,
                                 const LimitShares& share) noexcept;

// Largest factor (>= 1, <= max_rate) by which time may be sped up (feed override above 100 %)
// on a stretch of this element where the path speed, |acceleration| and |jerk| peak at v, a, j,
// keeping every axis within the shares of its limits.
double rate_cap(const ElementBounds& b, const AxisLimits& lim, double v, double a, double j,
                const LimitShares& share, double max_rate) noexcept;

}  // namespace motion
