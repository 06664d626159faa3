#include "motion/limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Share of an axis's acceleration that centripetal acceleration may take; the rest is left
// for speeding up and slowing down on curves. Blends are short, so their speed barely changes
// inside them and almost all of it goes to turning.
constexpr double kCentripetalShareArc = 0.8;
// Without a jerk limit speed changes on an arc are cheap (no ramp to build up), so turning gets
// more: 0.95 leaves sqrt(1 - 0.95^2) = 31 % for the tangential part at the cap (in quadrature).
// On tangent_arcs.ngc (radii 0.5-1.5 mm at F2400) 33.40 s at 0.8, 31.91 s at 0.95.
constexpr double kCentripetalShareArcNoJerk = 0.95;
constexpr double kCentripetalShareBlend = 0.95;
// Shares of the jerk budget for the v^3 p''' and 3 v a p'' terms of curved elements.
constexpr double kJerkCubicShareArc = 0.4;
constexpr double kJerkCrossShareArc = 0.3;
// Blends are short and mostly taken at constant speed: turning gets more of the jerk there.
constexpr double kJerkCubicShareBlend = 0.7;
constexpr double kJerkCrossShareBlend = 0.15;

// The loops below run over ElementBounds::axes only: every other axis has zero bounds and would
// add nothing to any minimum.

bool is_arc(const Element& e) {
    return e.kind == ElementKind::Arc;
}

// The limits of one set of rows: the axes, or the listed joints (slot j = joint j), each with
// its derivative bounds (ElementBounds of the element, or joint_bounds()). The functions over
// rows are always inlined: called out of line, their loops through references to the rows and
// to the running minima cost the planner 8 % more instructions on ex22 (callgrind).
struct Rows {
    const ElementBounds& b;
    const AxisArray& vel;
    const AxisArray& acc;
    const AxisArray& jerk;
};

// Smallest allowed v, v^2 and v^3 over the rows, into v1, v2, v3.
[[gnu::always_inline]] inline void speed_terms(const Rows& r, double centripetal, double cubic,
                                               const LimitShares& share, double& v1, double& v2,
                                               double& v3) {
    const ElementBounds& b = r.b;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (b.g1[k] > 0) v1 = std::min(v1, r.vel[k] / b.g1[k]);
        if (b.g2[k] > 0) v2 = std::min(v2, centripetal * share.acc * r.acc[k] / b.g2[k]);
        if (b.g3[k] > 0 && r.jerk[k] > 0)
            v3 = std::min(v3, cubic * share.jerk * r.jerk[k] / b.g3[k]);
    }
}

// joints: the joint rows, or null when the limits list none.
[[gnu::always_inline]] inline double speed_cap(const Element& e, const Rows& axes,
                                               const Rows* joints, const AxisLimits& lim,
                                               double feed, const LimitShares& share) {
    double blend = share.blend_centripetal > 0 ? share.blend_centripetal : kCentripetalShareBlend;
    // jerk_limited() asked only for arcs: it reads all nine axes
    double centripetal = !is_arc(e)          ? blend
                         : jerk_limited(lim) ? kCentripetalShareArc
                                             : kCentripetalShareArcNoJerk;
    double cubic = is_arc(e) ? kJerkCubicShareArc : kJerkCubicShareBlend;
    // Smallest allowed v, v^2 and v^3 over the axes (and joints) first, then one root of each.
    double v1 = feed > 0 ? feed : kInf, v2 = kInf, v3 = kInf;
    speed_terms(axes, centripetal, cubic, share, v1, v2, v3);
    if (joints) speed_terms(*joints, centripetal, cubic, share, v1, v2, v3);
    double v = v1;
    if (v2 < v * v) v = std::sqrt(v2);
    if (v3 < v * v * v) v = std::cbrt(v3);
    return v;
}

// Largest a with sqrt((a t)^2 + n^2) + a l <= m: the in-plane part of an arc's acceleration is
// a rotating vector, so tangential and centripetal parts add in quadrature, not linearly. The
// left side grows with a, so this is the root of (t^2 - l^2) a^2 + 2 m l a + n^2 - m^2 = 0 with
// m - a l >= 0, written in the form that stays exact for t = l and for l = 0; 0 when the
// centripetal part n alone uses up m.
double arc_axis_acc(double t, double l, double n, double m) {
    if (t == 0 && l == 0) return kInf;
    if (n >= m) return 0;
    return (m - n) * (m + n) / (m * l + std::sqrt(m * m * t * t - n * n * (t * t - l * l)));
}

[[gnu::always_inline]] inline double tangential_acc(const Element& e, const Rows& r, double v,
                                                    const LimitShares& share, double a) {
    const ElementBounds& b = r.b;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        double m = share.acc * r.acc[k];
        double n = v * v * b.g2[k];
        if (is_arc(e)) {
            a = std::min(a, arc_axis_acc(b.tangential_in_plane[k], b.linear[k], n, m));
        } else if (b.g1[k] > 0) {
            a = std::min(a, (m - n) / b.g1[k]);
        }
    }
    return a;
}

// Lowers a for the cross term of the jerk and j for the rest, row by row.
[[gnu::always_inline]] inline void jerk_terms(const Element& e, const Rows& r, double v,
                                              const LimitShares& share, double& a, double& j) {
    const ElementBounds& b = r.b;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (r.jerk[k] <= 0) continue;
        double m = share.jerk * r.jerk[k];
        double cross = is_arc(e) ? kJerkCrossShareArc : kJerkCrossShareBlend;
        if (b.g2[k] > 0) a = std::min(a, cross * m / (3 * v * b.g2[k]));
        if (b.g1[k] > 0) j = std::min(j, (m - 3 * v * a * b.g2[k] - v * v * v * b.g3[k]) / b.g1[k]);
    }
}

// Smallest allowed rate r, r^2 and r^3 over the rows, into r1, r2, r3.
[[gnu::always_inline]] inline void rate_terms(const Rows& r, double v, double a, double j,
                                              const LimitShares& share, double& r1, double& r2,
                                              double& r3) {
    const ElementBounds& b = r.b;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (b.g1[k] == 0 && b.g2[k] == 0) continue;
        double vk = v * b.g1[k];
        double ak = a * b.g1[k] + v * v * b.g2[k];
        if (vk > 0) r1 = std::min(r1, r.vel[k] / vk);
        if (ak > 0) r2 = std::min(r2, share.acc * r.acc[k] / ak);
        if (r.jerk[k] > 0) {
            double jk = j * b.g1[k] + 3 * v * a * b.g2[k] + v * v * v * b.g3[k];
            if (jk > 0) r3 = std::min(r3, share.jerk * r.jerk[k] / jk);
        }
    }
}

[[gnu::always_inline]] inline Rows axis_rows(const ElementBounds& b, const AxisLimits& lim) {
    return {b, lim.vel_mm_s, lim.acc_mm_s2, lim.jerk_mm_s3};
}
[[gnu::always_inline]] inline Rows joint_rows(const ElementBounds& jb, const JointLimits& joints) {
    return {jb, joints.vel_mm_s, joints.acc_mm_s2, joints.jerk_mm_s3};
}

// An element's limits under the axes' rows and, when given, the joints'.
[[gnu::always_inline]] inline ElementLimits limits_of(const Element& e, const Rows& axes,
                                                      const Rows* joints, const AxisLimits& lim,
                                                      double feed, const LimitShares& share) {
    ElementLimits out;
    double v = speed_cap(e, axes, joints, lim, feed, share);
    double a = tangential_acc(e, axes, v, share, kInf);
    if (joints) a = tangential_acc(e, *joints, v, share, a);
    double j = kInf;
    jerk_terms(e, axes, v, share, a, j);
    if (joints) jerk_terms(e, *joints, v, share, a, j);
    out.vcap_mm_s = v;
    out.tangent.acc_mm_s2 = a;
    out.tangent.jerk_mm_s3 = std::isfinite(j) ? j : 0;
    return out;
}

// With joints, out of line: the common case (none) then runs the code it ran before joints
// existed (ex22: 430 k instructions per planning pass; 444 k with one function for both).
[[gnu::noinline]] ElementLimits limits_with_joints(const Element& e, const ElementBounds& b,
                                                   const AxisLimits& lim, double feed,
                                                   const LimitShares& share) {
    const ElementBounds jb = joint_bounds(e, lim.joints);
    const Rows joints = joint_rows(jb, lim.joints);
    return limits_of(e, axis_rows(b, lim), &joints, lim, feed, share);
}

// The largest rate over the axes' rows and, when given, the joints' (see rate_cap()).
[[gnu::always_inline]] inline double rate_of(const Rows& axes, const Rows* joints, double v,
                                             double a, double j, const LimitShares& share,
                                             double max_rate) {
    // r scales velocity by r, acceleration by r^2 and jerk by r^3: collect the smallest
    // allowed r, r^2 and r^3 first, then take one root of each.
    double r1 = max_rate, r2 = kInf, r3 = kInf;
    rate_terms(axes, v, a, j, share, r1, r2, r3);
    if (joints) rate_terms(*joints, v, a, j, share, r1, r2, r3);
    double r = r1;
    if (r2 < r * r) r = std::sqrt(r2);
    if (r3 < r * r * r) r = std::cbrt(r3);
    return std::max(r, 1.0);
}

[[gnu::noinline]] double rate_cap_with_joints(const ElementBounds& b, const AxisLimits& lim,
                                              double v, double a, double j,
                                              const LimitShares& share, double max_rate) {
    const ElementBounds jb = joint_bounds(b, lim.joints);
    const Rows joints = joint_rows(jb, lim.joints);
    return rate_of(axis_rows(b, lim), &joints, v, a, j, share, max_rate);
}

// max(worst, |(M dT)_j| / (share x acc_j)) over the joints.
[[gnu::noinline]] double joint_turn_worst(const AxisArray& dt_turn, const JointLimits& joints,
                                          double share, double worst) {
    for (int j = 0; j < joints.count; ++j)
        worst = std::max(
            worst, std::fabs(joint_component(joints, j, dt_turn)) / (share * joints.acc_mm_s2[j]));
    return worst;
}

bool bad_limit(double x) {
    return !(x >= 0) || !std::isfinite(x);
}

}  // namespace

ElementLimits element_limits(const Element& e, const ElementBounds& b, const AxisLimits& lim,
                             double feed, const LimitShares& share) noexcept {
    if (lim.joints.count > 0) return limits_with_joints(e, b, lim, feed, share);
    return limits_of(e, axis_rows(b, lim), nullptr, lim, feed, share);
}

double parabola_cut_for_speed_mm(const AxisArray& dt_turn, double v_mm_s, const AxisLimits& lim,
                                 const LimitShares& share) noexcept {
    double blend = share.blend_centripetal > 0 ? share.blend_centripetal : kCentripetalShareBlend;
    double worst = 0;  // max_k |dT_k| / (allowed acceleration of k)
    for (int k = 0; k < kAxes; ++k)
        worst = std::max(worst, std::fabs(dt_turn[k]) / (blend * share.acc * lim.acc_mm_s2[k]));
    // The parabola's second derivative is the constant dT / 2l: joint j sees (M dT)_j / 2l.
    if (lim.joints.count > 0)
        worst = joint_turn_worst(dt_turn, lim.joints, blend * share.acc, worst);
    return v_mm_s * v_mm_s * worst / 2;
}

double rate_cap(const ElementBounds& b, const AxisLimits& lim, double v, double a, double j,
                const LimitShares& share, double max_rate) noexcept {
    if (lim.joints.count > 0) return rate_cap_with_joints(b, lim, v, a, j, share, max_rate);
    return rate_of(axis_rows(b, lim), nullptr, v, a, j, share, max_rate);
}

double joint_pass_speed_cap(const AxisArray& t1, const AxisArray& t2, const JointLimits& joints,
                            double cap_mm_s) noexcept {
    for (int j = 0; j < joints.count; ++j) {
        double t = std::max(std::fabs(joint_component(joints, j, t1)),
                            std::fabs(joint_component(joints, j, t2)));
        if (t > 0) cap_mm_s = std::min(cap_mm_s, joints.vel_mm_s[j] / t);
    }
    return cap_mm_s;
}

void joint_turn_and_shift(const AxisArray& t1, const AxisArray& t2, const AxisArray& n1,
                          const AxisArray& n2, const JointLimits& joints, double& turn,
                          double& shift) noexcept {
    for (int j = 0; j < joints.count; ++j) {
        const double dt =
            std::fabs(joint_component(joints, j, t2) - joint_component(joints, j, t1));
        if (dt > 0) turn = std::min(turn, joints.acc_mm_s2[j] / dt);
        shift = std::max(shift, std::max(std::fabs(joint_component(joints, j, n1)),
                                         std::fabs(joint_component(joints, j, n2))) /
                                    joints.acc_mm_s2[j]);
    }
}

IndependentShares independent_axes_shares(const AxisLimits& lim,
                                          const std::array<bool, kAxes>& moving) noexcept {
    IndependentShares out;
    const JointLimits& jl = lim.joints;
    for (int j = 0; j < jl.count; ++j) {
        double vel = 0, acc = 0;  // what the moving axes could ask of joint j at their limits
        for (int k = 0; k < kAxes; ++k) {
            if (!moving[k]) continue;
            const double m = std::fabs(jl.rows[j][k]);
            vel += m * lim.vel_mm_s[k];
            acc += m * lim.acc_mm_s2[k];
        }
        if (vel > jl.vel_mm_s[j]) out.vel = std::min(out.vel, jl.vel_mm_s[j] / vel);
        if (acc > jl.acc_mm_s2[j]) out.acc = std::min(out.acc, jl.acc_mm_s2[j] / acc);
    }
    return out;
}

bool jerk_limited(const AxisLimits& lim) noexcept {
    auto any = [](const AxisArray& jerk, int n) {
        return std::any_of(jerk.begin(), jerk.begin() + n, [](double j) { return j > 0; });
    };
    return any(lim.jerk_mm_s3, kAxes) || any(lim.joints.jerk_mm_s3, lim.joints.count);
}

AxisLimits joint_space_limits(const JointLimits& joints) noexcept {
    AxisLimits out;
    out.vel_mm_s = joints.vel_mm_s;
    out.acc_mm_s2 = joints.acc_mm_s2;
    out.jerk_mm_s3 = joints.jerk_mm_s3;
    return out;
}

ElementBounds joint_bounds(const Element& e, const JointLimits& joints) noexcept {
    // Every element kind's bounds are functions of its vectors (origin, a, b, c, end) that stay
    // linear under a linear map (a line's direction, an arc's in-plane frame and helix travel, a
    // blend's tangents, a Bezier's control points): the mapped element's bounds are the joints'.
    Element q = element_copy(e);
    auto map = [&](const AxisArray& v, AxisArray& out) {
        out.fill(0);
        for (int j = 0; j < joints.count; ++j) out[j] = joint_component(joints, j, v);
    };
    map(e.origin, q.origin);
    map(e.a, q.a);
    map(e.b, q.b);
    map(e.c, q.c);
    map(e.end, q.end);
    return bounds(q);
}

ElementBounds joint_bounds(const ElementBounds& b, const JointLimits& joints) noexcept {
    ElementBounds out;
    AxisArray* const outs[] = {&out.g1, &out.g2, &out.g3, &out.tangential_in_plane, &out.linear};
    const AxisArray* const ins[] = {&b.g1, &b.g2, &b.g3, &b.tangential_in_plane, &b.linear};
    for (int n = 0; n < 5; ++n) {
        AxisArray& o = *outs[n];
        const AxisArray& g = *ins[n];
        o.fill(0);
        for (int j = 0; j < joints.count; ++j) {
            const AxisArray& m = joints.rows[static_cast<std::size_t>(j)];
            for (int i = 0; i < b.axis_count; ++i) o[j] += std::fabs(m[b.axes[i]]) * g[b.axes[i]];
        }
    }
    out.axis_count = 0;
    for (int j = 0; j < joints.count; ++j)
        if (out.g1[j] > 0 || out.g2[j] > 0 || out.g3[j] > 0)
            out.axes[out.axis_count++] = static_cast<std::uint8_t>(j);
    return out;
}

void validate_joints(const JointLimits& joints) {
    if (joints.count < 0 || joints.count > kAxes)
        throw std::invalid_argument("joint limits: " + std::to_string(joints.count) +
                                    " joints listed, at most " + std::to_string(kAxes));
    for (int j = 0; j < joints.count; ++j) {
        const std::string name = "joint row " + std::to_string(j);
        if (!(joints.vel_mm_s[j] > 0) || !(joints.acc_mm_s2[j] > 0) ||
            !std::isfinite(joints.vel_mm_s[j]) || !std::isfinite(joints.acc_mm_s2[j]))
            throw std::invalid_argument(name +
                                        ": velocity and acceleration limits must be > 0 "
                                        "and finite");
        if (bad_limit(joints.jerk_mm_s3[j]))
            throw std::invalid_argument(name + ": jerk limit must be >= 0 (0 = unlimited)");
        for (double m : joints.rows[j])
            if (!std::isfinite(m))
                throw std::invalid_argument(name + ": the joint map is not finite");
    }
}

void set_linear_joints(AxisLimits& lim, std::span<const AxisArray> rows,
                       std::span<const JointLimit> joints) {
    if (rows.size() != joints.size())
        throw std::invalid_argument("joint limits: " + std::to_string(joints.size()) +
                                    " joints' limits for a map of " + std::to_string(rows.size()));
    if (rows.size() > static_cast<std::size_t>(kAxes))
        throw std::invalid_argument("joint limits: more than " + std::to_string(kAxes) + " joints");
    JointLimits out;
    for (std::size_t j = 0; j < rows.size(); ++j) {
        const JointLimit& own = joints[j];
        if (bad_limit(own.vel_mm_s) || bad_limit(own.acc_mm_s2) || bad_limit(own.jerk_mm_s3))
            throw std::invalid_argument("joint " + std::to_string(j) +
                                        ": limits must be >= 0 and finite (0 = unlimited)");
        // What the axes allow the joint anyway: sum_k |M_jk| limit_k (infinite jerk when an
        // axis it follows has no jerk limit).
        double vel = 0, acc = 0, jerk = 0;
        for (int k = 0; k < kAxes; ++k) {
            const double m = std::fabs(rows[j][k]);
            if (m == 0) continue;
            vel += m * lim.vel_mm_s[k];
            acc += m * lim.acc_mm_s2[k];
            jerk += lim.jerk_mm_s3[k] > 0 ? m * lim.jerk_mm_s3[k] : kInf;
        }
        if (vel == 0) continue;  // a joint no axis moves
        const bool tighter = (own.vel_mm_s > 0 && own.vel_mm_s < vel) ||
                             (own.acc_mm_s2 > 0 && own.acc_mm_s2 < acc) ||
                             (own.jerk_mm_s3 > 0 && own.jerk_mm_s3 < jerk);
        if (!tighter) continue;
        const auto n = static_cast<std::size_t>(out.count++);
        out.rows[n] = rows[j];
        out.vel_mm_s[n] = own.vel_mm_s > 0 ? std::min(own.vel_mm_s, vel) : vel;
        out.acc_mm_s2[n] = own.acc_mm_s2 > 0 ? std::min(own.acc_mm_s2, acc) : acc;
        out.jerk_mm_s3[n] = own.jerk_mm_s3 > 0    ? std::min(own.jerk_mm_s3, jerk)
                            : std::isfinite(jerk) ? jerk
                                                  : 0;
    }
    validate_joints(out);
    lim.joints = out;
}

}  // namespace motion
