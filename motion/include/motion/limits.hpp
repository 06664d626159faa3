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
//
// Joints of a linear kinematics (AxisLimits::joints, q = M p) are limited the same way: joint
// j sees the curve q_j(s) = sum_k M_jk p_k(s), whose derivative bounds joint_bounds() gives, and
// every function here takes the smaller of what the axes and what the joints allow.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>

#include "motion/geometry.hpp"
#include "motion/profile.hpp"
#include "motion/types.hpp"

namespace motion {

// One joint's limits as a machine's settings give them; 0 = unlimited.
struct JointLimit {
    double vel_mm_s = 0;
    double acc_mm_s2 = 0;
    double jerk_mm_s3 = 0;
};

// Sets lim.joints from a linear kinematics' joint map (one row of M per joint, as
// Kinematics::linear_map() gives it) and the joints' limits, after lim's axis limits are set.
// Each joint keeps the smaller of its own limit and what the axes allow it anyway
// (sum_k |M_jk| limit_k, the most it can see while every axis keeps its limit); a joint whose
// own limits are all no tighter than that is left out, so the plans of a machine whose motors
// are at least as fast as its axes do not change. Configuration world: throws
// std::invalid_argument for a negative or non-finite limit, more than kAxes joints, or rows
// and limits of different counts.
void set_linear_joints(AxisLimits& lim, std::span<const AxisArray> rows,
                       std::span<const JointLimit> joints);

// Throws std::invalid_argument unless lim.joints is as set_linear_joints() leaves it (for
// limits built by hand).
void validate_joints(const JointLimits& joints);

// Whether any axis or listed joint has a jerk limit: the planner's and the sampler's jerk mode.
bool jerk_limited(const AxisLimits& lim) noexcept;

// Joint j's part of a vector of axis values (a tangent, a change of tangent, a normal):
// sum_k rows[j][k] v[k].
inline double joint_component(const JointLimits& joints, int j, const AxisArray& v) noexcept {
    const AxisArray& m = joints.rows[static_cast<std::size_t>(j)];
    double x = 0;
    for (int k = 0; k < kAxes; ++k) x += m[k] * v[k];
    return x;
}

// Calls f(vel, acc, jerk) with the limits of every axis, then of every listed joint: for bounds
// that hold whatever the plan does (each axis and joint within its share of its limits).
template <class F>
void for_each_limit(const AxisLimits& lim, F&& f) {
    for (int k = 0; k < kAxes; ++k) f(lim.vel_mm_s[k], lim.acc_mm_s2[k], lim.jerk_mm_s3[k]);
    const JointLimits& jl = lim.joints;
    for (int j = 0; j < jl.count; ++j) f(jl.vel_mm_s[j], jl.acc_mm_s2[j], jl.jerk_mm_s3[j]);
}

// The listed joints' limits as an AxisLimits whose axis j is joint j (slots past the count and
// its own joints empty), for code written per axis that runs once more over joint_bounds().
AxisLimits joint_space_limits(const JointLimits& joints) noexcept;

// For axes that move each on its own (the probe's conditional move, ProbeJog), each at up to
// the same share of its own velocity and acceleration limits: the largest shares (<= 1) that
// keep every listed joint within its limits whatever the moving axes do (joint j sees at most
// sum over moving k of |M_jk| share limit_k). {1, 1} without joints.
struct IndependentShares {
    double vel = 1;
    double acc = 1;
};
IndependentShares independent_axes_shares(const AxisLimits& lim,
                                          const std::array<bool, kAxes>& moving) noexcept;

// The derivative bounds of element e as the listed joints see it, joint j in place of axis j:
// the bounds of the element mapped through M, exact for every element kind (each kind's bounds
// are functions of vectors that M maps linearly, e.g. a CoreXY 45 degree line: 2 for joint 0
// (X + Y), 0 for joint 1 (X - Y) per unit of path). Realtime-safe.
ElementBounds joint_bounds(const Element& e, const JointLimits& joints) noexcept;
// The same from the axis bounds alone: sum_k |M_jk| g_k, never below the exact ones.
ElementBounds joint_bounds(const ElementBounds& b, const JointLimits& joints) noexcept;

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
// Joints are bounded through the axis bounds (joint_bounds(b, ...)): never above their
// limits, on a diagonal CoreXY line never below the cap either joint alone would give.
double rate_cap(const ElementBounds& b, const AxisLimits& lim, double v, double a, double j,
                const LimitShares& share, double max_rate) noexcept;

// Highest speed at which a corner between the unit tangents t1 and t2 could be passed without
// an axis or joint going faster than its velocity limit on either side: the smaller of cap and
// every vel / max(|t1|, |t2|) (component-wise, joints through their rows). Inline for the
// planner's corners; the joints' part out of line.
double joint_pass_speed_cap(const AxisArray& t1, const AxisArray& t2, const JointLimits& joints,
                            double cap_mm_s) noexcept;
inline double pass_speed_cap(const AxisArray& t1, const AxisArray& t2, const AxisLimits& lim,
                             double cap_mm_s) noexcept {
    for (int k = 0; k < kAxes; ++k) {
        double t = std::max(std::fabs(t1[k]), std::fabs(t2[k]));
        if (t > 0) cap_mm_s = std::min(cap_mm_s, lim.vel_mm_s[k] / t);
    }
    return lim.joints.count > 0 ? joint_pass_speed_cap(t1, t2, lim.joints, cap_mm_s) : cap_mm_s;
}

// An offset corner's frame (planner.cpp) over the joints: turn lowered to every joint's
// acc / |(M (t2 - t1))_j|, shift raised to max(|(M n1)_j|, |(M n2)_j|) / acc.
void joint_turn_and_shift(const AxisArray& t1, const AxisArray& t2, const AxisArray& n1,
                          const AxisArray& n2, const JointLimits& joints, double& turn,
                          double& shift) noexcept;

}  // namespace motion
