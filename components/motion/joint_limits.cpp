#include "joint_limits.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>
#include <stdexcept>

#include "kins_link.hpp"

namespace motioncomp {

namespace {

// Piece sizes within which a joint is close to a parabola (see the header).
constexpr double kPieceSweepRad = std::numbers::pi / 2;  // 90 degrees of arc
constexpr double kPieceRotaryDeg = 10;                   // of A, B or C travel
constexpr int kMaxPieces = 1 << 16;                      // a 650 000-degree C move stays cheap
// Allowance for the curvature between samples, as a multiple of the midpoint deviation.
constexpr double kCurvatureFactor = 2;
// Below this midpoint deviation an interval is not halved again: the bound of the check.
constexpr double kLeafDeviation = 1e-6;
constexpr int kMaxDepth = 40;
// Rounding of the inverse kinematics (the servo check's kJointLimitRoundingMm).
constexpr double kRounding = 1e-9;
constexpr int kFirstRotary = 3, kLastRotary = 5;  // A, B, C
// Joint rates (see "Joint rates at plan time" in the header).
constexpr double kRateStep = 1e-2;       // mm or degrees along the tangent
constexpr double kRateTolerance = 1e-3;  // allowance 2 |d| within this share of the bound
constexpr double kRateFloor = 1e-6;      // ... or below this (joint units per mm, per mm^2)
constexpr int kMaxRateDepth = 10;        // halvings of a piece
constexpr double kSlowestCapMmS = 1e-6;  // the planner needs a speed > 0

// The largest |f| on an interval from f at its ends and middle (the parabola allowance), and
// whether the allowance is small against it or against `scale`, the largest |f| at the move's
// piece ends (a joint's rate where it is far below its own peak decides no cap).
struct RateBound {
    double bound;
    bool fine;
};
RateBound rate_bound(double f0, double fm, double f1, double scale) noexcept {
    const double d = std::fabs(fm - 0.5 * (f0 + f1));
    const double hi = std::max({f0, fm, f1}) + kCurvatureFactor * d;
    const double lo = std::min({f0, fm, f1}) - kCurvatureFactor * d;
    const double bound = std::max(std::fabs(hi), std::fabs(lo));
    // NaN (a point the kinematics cannot reach) is never fine: halved to the depth limit.
    return {bound, kCurvatureFactor * d <= kRateTolerance * std::max(bound, scale) + kRateFloor};
}

int piece_count(const motion::Element& e, const motion::AxisArray& start) {
    double pieces = 1;
    if (e.kind == motion::ElementKind::Arc)
        pieces = std::max(pieces, std::ceil(std::fabs(e.sweep_rad) / kPieceSweepRad));
    for (int k = kFirstRotary; k <= kLastRotary; ++k)
        pieces = std::max(pieces, std::ceil(std::fabs(e.end[k] - start[k]) / kPieceRotaryDeg));
    return static_cast<int>(std::min(pieces, static_cast<double>(kMaxPieces)));
}

}  // namespace

JointLimitCheck::JointLimitCheck(JointLimitConfig cfg) : cfg_(std::move(cfg)) {
    if (!cfg_.kins) return;
    joints_ = cfg_.kins->kins().joint_count();
    if (joints_ > kMaxJoints)
        throw std::invalid_argument("the kinematics has " + std::to_string(joints_) +
                                    " joints; motion checks at most " + std::to_string(kMaxJoints));
    if (cfg_.min_limit.size() != joints_ || cfg_.max_limit.size() != joints_)
        throw std::invalid_argument("joint limits given for another number of joints");
    if (!cfg_.max_velocity.empty() &&
        (cfg_.max_velocity.size() != joints_ || cfg_.max_acceleration.size() != joints_))
        throw std::invalid_argument("joint rate limits given for another number of joints");
    if (!(cfg_.max_rate >= 1 && std::isfinite(cfg_.max_rate)))
        throw std::invalid_argument("max_rate must be >= 1 and finite");
}

void JointLimitCheck::set_tool_offset(double tool_offset_mm) noexcept {
    if (cfg_.kins) cfg_.kins->set_tool_offset(tool_offset_mm);
    last_end_known_ = false;  // the same axes map to other joints now
}

void JointLimitCheck::joints_at(const motion::Element& e, double s_mm, Joints& out) const noexcept {
    cfg_.kins->kins().inverse(motion::point_at(e, s_mm), std::span<double>(out.data(), joints_));
}

// Inside means within [min - allowance, max + allowance] plus rounding, the allowance being the
// start's own distance outside, except at the end, which must be inside. NaN is outside.
std::optional<JointViolation> JointLimitCheck::beyond(const motion::Element& e, double s_mm,
                                                      const Joints& j, bool at_end) const noexcept {
    for (std::size_t n = 0; n < joints_; ++n) {
        const double above = at_end ? 0 : allow_above_[n];
        const double below = at_end ? 0 : allow_below_[n];
        const bool high = !(j[n] <= cfg_.max_limit[n] + above + kRounding);
        const bool low = !(j[n] >= cfg_.min_limit[n] - below - kRounding);
        if (!high && !low) continue;
        return JointViolation{static_cast<int>(n), j[n], high, motion::point_at(e, s_mm), s_mm};
    }
    return std::nullopt;
}

std::optional<JointViolation> JointLimitCheck::refine(const motion::Element& e, double s0,
                                                      const Joints& j0, double s1, const Joints& j1,
                                                      int depth) const noexcept {
    const double sm = 0.5 * (s0 + s1);
    Joints jm;
    joints_at(e, sm, jm);
    if (auto v = beyond(e, sm, jm, false)) return v;
    bool cleared = true;
    for (std::size_t n = 0; n < joints_ && cleared; ++n) {
        const double d = std::fabs(jm[n] - 0.5 * (j0[n] + j1[n]));
        if (d < kLeafDeviation) continue;  // samples inside: within the bound of the check
        const double hi = std::max({j0[n], j1[n], jm[n]}) + kCurvatureFactor * d;
        const double lo = std::min({j0[n], j1[n], jm[n]}) - kCurvatureFactor * d;
        cleared = hi <= cfg_.max_limit[n] + allow_above_[n] + kRounding &&
                  lo >= cfg_.min_limit[n] - allow_below_[n] - kRounding;
    }
    if (cleared || depth >= kMaxDepth) return std::nullopt;
    if (auto v = refine(e, s0, j0, sm, jm, depth + 1)) return v;
    return refine(e, sm, jm, s1, j1, depth + 1);
}

bool JointLimitCheck::corners_inside(const motion::AxisArray& from_mm,
                                     const motion::AxisArray& span_mm, double f) const noexcept {
    std::array<int, motion::kAxes> moving{};
    int count = 0;
    for (int k = 0; k < motion::kAxes; ++k)
        if (span_mm[k] != 0) moving[count++] = k;
    Joints j;
    for (unsigned corner = 1; corner < (1u << count); ++corner) {
        motion::AxisArray p = from_mm;
        for (int b = 0; b < count; ++b)
            if (corner & (1u << b)) p[moving[b]] += f * span_mm[moving[b]];
        cfg_.kins->kins().inverse(p, std::span<double>(j.data(), joints_));
        for (std::size_t n = 0; n < joints_; ++n)
            if (!(j[n] <= cfg_.max_limit[n] + allow_above_[n] + kRounding) ||
                !(j[n] >= cfg_.min_limit[n] - allow_below_[n] - kRounding))
                return false;
    }
    return true;
}

double JointLimitCheck::box_scale(const motion::AxisArray& from_mm,
                                  const motion::AxisArray& span_mm) {
    if (!cfg_.kins) return 1;
    Joints j0;
    cfg_.kins->kins().inverse(from_mm, std::span<double>(j0.data(), joints_));
    for (std::size_t n = 0; n < joints_; ++n) {
        allow_above_[n] = std::max(0.0, j0[n] - cfg_.max_limit[n]);
        allow_below_[n] = std::max(0.0, cfg_.min_limit[n] - j0[n]);
    }
    if (corners_inside(from_mm, span_mm, 1)) return 1;
    // Halved until inside first: a travel up to an axis limit of 1e99 (none set) may be cut
    // down to millimetres; then bisected to 1e-12 of what is kept.
    double inside = 0.5, outside = 1;
    while (!corners_inside(from_mm, span_mm, inside)) {
        outside = inside;
        inside *= 0.5;
        if (inside < 1e-300) return 0;  // the corners at f = 0 are the start itself
    }
    while (outside - inside > 1e-12 * inside) {
        const double f = 0.5 * (inside + outside);
        (corners_inside(from_mm, span_mm, f) ? inside : outside) = f;
    }
    return inside;
}

// The point of the path where joint v.joint is farthest beyond what the move was allowed (the
// limit; points before the end also the start's own distance outside): what the message names.
// Branch and bound with the same curvature allowance as the check (an interval can exceed its
// samples by at most 2 |d|), from v's own point; only for a refused move.
JointViolation JointLimitCheck::farthest(const motion::Element& e, int pieces,
                                         const JointViolation& v) const noexcept {
    const auto n = static_cast<std::size_t>(v.joint);
    const double sign = v.above ? 1 : -1;
    const double limit = v.above ? cfg_.max_limit[n] : cfg_.min_limit[n];
    const double allow = v.above ? allow_above_[n] : allow_below_[n];
    Joints j;
    // How far beyond the limit, less the allowance every point but the end has.
    auto beyond_by = [&](double s) {
        joints_at(e, s, j);
        return sign * (j[n] - limit) - allow;
    };
    Farthest f{v.s_mm, beyond_by(v.s_mm) + (v.s_mm < e.length_mm ? 0 : allow)};
    if (const double at_end = beyond_by(e.length_mm) + allow; at_end > f.excess)
        f = {e.length_mm, at_end};
    double s0 = 0, g0 = beyond_by(0);
    for (int i = 1; i <= pieces; ++i) {
        const double s1 = i == pieces ? e.length_mm : e.length_mm * i / pieces;
        const double g1 = beyond_by(s1);
        maximise(e, beyond_by, s0, g0, s1, g1, 0, f);
        s0 = s1;
        g0 = g1;
    }
    JointViolation out = v;
    joints_at(e, f.s_mm, j);
    out.position = j[n];
    out.at_mm = motion::point_at(e, f.s_mm);
    out.s_mm = f.s_mm;
    return out;
}

template <class Excess>
void JointLimitCheck::maximise(const motion::Element& e, Excess& excess, double s0, double g0,
                               double s1, double g1, int depth, Farthest& f) const noexcept {
    const double sm = 0.5 * (s0 + s1);
    const double gm = excess(sm);
    if (gm > f.excess) f = {sm, gm};
    const double d = std::fabs(gm - 0.5 * (g0 + g1));
    if (std::max({g0, g1, gm}) + kCurvatureFactor * d <= f.excess + 1e-12) return;
    if (depth >= 2 * kMaxDepth || s1 - s0 <= 1e-12 * e.length_mm) return;
    maximise(e, excess, s0, g0, sm, gm, depth + 1, f);
    maximise(e, excess, sm, gm, s1, g1, depth + 1, f);
}

// g = J(p) p' and h = D2q(p)[p', p'] (q the inverse kinematics, p(s) the path) by central
// differences along p'. h is the kinematics' own curvature: what the joints add to the path's
// (J(p) p'', which the planner limits through the axes); zero for a kinematics linear in the
// axes that move.
void JointLimitCheck::rates_at(const motion::Element& e, double s_mm, Rates& out) const noexcept {
    motion::CurvePoint cp;
    motion::evaluate_upto(e, s_mm, 1, cp);
    const motion::Kinematics& k = cfg_.kins->kins();
    Joints q0, qp, qm;
    auto along = [&](double step, Joints& q) {
        motion::AxisArray p = cp.p;
        for (int a = 0; a < motion::kAxes; ++a) p[a] += step * cp.d1[a];
        k.inverse(p, std::span<double>(q.data(), joints_));
    };
    k.inverse(cp.p, std::span<double>(q0.data(), joints_));
    along(kRateStep, qp);
    along(-kRateStep, qm);
    for (std::size_t n = 0; n < joints_; ++n) {
        out.g[n] = (qp[n] - qm[n]) / (2 * kRateStep);
        out.h[n] = (qp[n] - 2 * q0[n] + qm[n]) / (kRateStep * kRateStep);
    }
}

void JointLimitCheck::bound_rates(const motion::Element& e, double s0, const Rates& r0, double s1,
                                  const Rates& r1, int depth, const Rates& scale, Joints& g_max,
                                  Joints& h_max) const noexcept {
    const double sm = 0.5 * (s0 + s1);
    Rates rm;
    rates_at(e, sm, rm);
    Joints g, h;
    bool fine = true;
    for (std::size_t n = 0; n < joints_; ++n) {
        const RateBound bg = rate_bound(r0.g[n], rm.g[n], r1.g[n], scale.g[n]);
        const RateBound bh = rate_bound(r0.h[n], rm.h[n], r1.h[n], scale.h[n]);
        g[n] = bg.bound;
        h[n] = bh.bound;
        fine = fine && bg.fine && (cfg_.max_acceleration[n] <= 0 || bh.fine);
    }
    if (fine || depth >= kMaxRateDepth) {
        for (std::size_t n = 0; n < joints_; ++n) {
            // std::max would drop a NaN bound: the joint is then unbounded.
            g_max[n] = std::isnan(g[n]) ? INFINITY : std::max(g_max[n], g[n]);
            h_max[n] = std::isnan(h[n]) ? INFINITY : std::max(h_max[n], h[n]);
        }
        return;
    }
    bound_rates(e, s0, r0, sm, rm, depth + 1, scale, g_max, h_max);
    bound_rates(e, sm, rm, s1, r1, depth + 1, scale, g_max, h_max);
}

double JointLimitCheck::speed_cap_mm_s(const motion::Element& e,
                                       double axes_speed_mm_s) const noexcept {
    if (!cfg_.kins || cfg_.max_velocity.size() != joints_ || !(e.length_mm > 0)) return INFINITY;
    Joints g_max{}, h_max{};
    const int pieces = piece_count(e, motion::point_at(e, 0));
    auto piece_end = [&](int i) { return i == pieces ? e.length_mm : e.length_mm * i / pieces; };
    // First the scale: each joint's largest |g| and |h| at the piece ends.
    Rates r0, r1, scale{};
    for (int i = 0; i <= pieces; ++i) {
        rates_at(e, piece_end(i), r1);
        for (std::size_t n = 0; n < joints_; ++n) {
            scale.g[n] = std::max(scale.g[n], std::fabs(r1.g[n]));
            scale.h[n] = std::max(scale.h[n], std::fabs(r1.h[n]));
        }
    }
    rates_at(e, 0, r0);
    double s0 = 0;
    for (int i = 1; i <= pieces; ++i) {
        const double s1 = piece_end(i);
        rates_at(e, s1, r1);
        bound_rates(e, s0, r0, s1, r1, 0, scale, g_max, h_max);
        s0 = s1;
        r0 = r1;
    }
    // The axes keep the path speed at or below axes_speed_mm_s at any override: a joint whose
    // own speed bound is not below that needs no cap; one that is gets it at the highest
    // override.
    double cap = INFINITY;
    for (std::size_t n = 0; n < joints_; ++n) {
        if (const double v = cfg_.max_velocity[n]; v > 0 && g_max[n] > 0)
            cap = std::min(cap, v / g_max[n]);
        if (const double a = cfg_.max_acceleration[n]; a > 0 && h_max[n] > 0)
            cap = std::min(cap, std::sqrt(kCurvatureAccShare * a / h_max[n]));
    }
    // A joint that mirrors an axis (C, or X on a level table) has the axis's bound, give or
    // take the allowance: within it the axes' speed is kept (the joint may then reach
    // 1 + kRateTolerance times its limit, the servo check's slack).
    if (!(cap < axes_speed_mm_s * (1 - kRateTolerance))) return INFINITY;
    return std::max(cap / cfg_.max_rate, kSlowestCapMmS);
}

std::optional<JointViolation> JointLimitCheck::check(const motion::Element& e) {
    if (!cfg_.kins || !(e.length_mm > 0)) return std::nullopt;
    Joints j0, j1;
    const motion::AxisArray start = motion::point_at(e, 0);
    // A move mostly starts where the last one checked ended: its joints are known.
    if (last_end_known_ && start == last_end_mm_)
        j0 = last_end_joints_;
    else
        cfg_.kins->kins().inverse(start, std::span<double>(j0.data(), joints_));
    for (std::size_t n = 0; n < joints_; ++n) {
        allow_above_[n] = std::max(0.0, j0[n] - cfg_.max_limit[n]);
        allow_below_[n] = std::max(0.0, cfg_.min_limit[n] - j0[n]);
    }
    const int pieces = piece_count(e, start);
    double s0 = 0;
    for (int i = 1; i <= pieces; ++i) {
        const double s1 = i == pieces ? e.length_mm : e.length_mm * i / pieces;
        joints_at(e, s1, j1);
        auto v = beyond(e, s1, j1, i == pieces);
        if (!v) v = refine(e, s0, j0, s1, j1, 0);
        if (v) return farthest(e, pieces, *v);
        s0 = s1;
        j0 = j1;
    }
    last_end_mm_ = e.end;  // what point_at gives at the end of a line or an arc
    last_end_joints_ = j0;
    last_end_known_ = true;
    return std::nullopt;
}

}  // namespace motioncomp
