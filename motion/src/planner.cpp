#include "motion/planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>

#include "root.hpp"

namespace motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinLength_mm = 1e-9;  // shorter moves are dropped as no motion
constexpr double kTangentEps = 1e-12;   // max per-axis tangent difference treated as smooth
// The blend's largest distance from the programmed lines is (3/16) l sin(angle) (geometry.hpp).
constexpr double kBlendDeviationPerL = 3.0 / 16.0;
constexpr double kParabolaDeviationPerL = 1.0 / 4.0;
// Turns sharper than this (about 170 degrees) between two lines are exact stops.
constexpr double kReversalCos = -0.985;
// A kink whose allowed speed is below this fraction of the feed is taken as an exact stop.
constexpr double kKinkStopFraction = 0.02;
// Jerk-limited elements share one S-curve profile when their limits are within this ratio.
constexpr double kJoinRatio = 0.8;
constexpr double kJoinSpeedRatio = 0.999;
constexpr std::size_t kMaxGroupItems = 256;
// Corners with an arc are blended when sin(angle) is below this (sharper ones are stopped at).
constexpr double kMaxArcBlendSin = 1.35;
// Share of an arc a corner blend may take (less than half: an arc never vanishes).
constexpr double kMaxArcTrimShare = 0.45;
// Checking a blend with an arc: it must provably stay within kDeviationMargin of the tolerance
// from the programmed moves' last and first kDeviationReach * l (bezier_within, geometry.hpp),
// else l shrinks by 0.7, at most kBlendAttempts times.
constexpr double kDeviationReach = 2;
constexpr double kDeviationMargin = 0.995;
constexpr int kBlendAttempts = 12;
// Without a jerk limit a corner blend is cut for this much more than the speed either move
// allows at the corner. Between moves of one feed a longer cut costs nothing at the corner, and
// the margin leaves the blend over half its acceleration for speed changes at that speed
// (surface_3d: 9.74 s at 1.05, 9.64 s at 1.5). Between a rapid and a feed move (or two feeds)
// the blend runs at the slower feed, so it is cut as short as will do (ex08: 84.110 s at 1.05,
// 84.128 s at 1.5): with an arc for this margin (a Bezier turns a little harder than the
// parabola), between two lines for exactly that feed (classify).
constexpr double kCornerSpeedMargin = 1.5;
constexpr double kMixedCornerSpeedMargin = 1.05;
constexpr double kSpeedCutFloor = 1.0 / 16;
// Share of the acceleration an isolated corner blend spends turning (see close_piece).
constexpr double kIsolatedBlendCentripetal = 0.99;
// The first shrink step, and after a later one that succeeded, this many bisections towards
// the cut that failed.
constexpr double kBlendFirstShrink = 0.97;
constexpr int kBlendBisections = 3;
// Offset corners (two lines, no jerk limit, offset_corner): the lines are moved up to
// kOffsetShare of the tolerance outwards (at least kOffsetMinShare of it) so that the parabola
// between them may cut twice as deep; everything is proved within kOffsetProofShare of the
// tolerance of the programmed lines. Turns up to about 90 degrees (cos >= kOffsetMinCos).
// The shifts onto the offset lines and back are cut for kShiftSpeedFactor times the corner's
// speed on kShiftCentripetal of the acceleration (the rest slows down and speeds up the tool
// there); measured on the bench programs (2 x to 6 x on 0.2 to 0.7): 3 x at 0.5 is best on
// pocket_sharp and within 6 ms of the best on the others (docs/benchmarks.md). Where a line has
// less room a shift is shortened down to kShiftMinSpeedFactor x the corner's speed (2 x: tp_default
// -5 ms, pocket_sharp -18 ms against no shortening; 1.2 x and 0.8 x: slower again), below
// that the parabola is used.
constexpr double kOffsetShare = 0.99;
constexpr double kOffsetMinShare = 0.1;
constexpr double kOffsetProofShare = 0.995;
constexpr double kOffsetMinCos = -0.02;
constexpr double kShiftSpeedFactor = 3;
constexpr double kShiftCentripetal = 0.5;
constexpr double kShiftMinSpeedFactor = 2;
// A lane change onto or off a line whose outward normal lies at least kAxisShiftMinNormal along
// one axis moves the tool along that axis only (lane_change_direction): on tp_default's sine
// rows (11 degrees off X at the X0 row end) a shift along the normal also moves X, whose
// acceleration the shift then shares with its turning sideways (898 instead of 990 mm/s^2 for
// 19 ms). A line of at most kShortMoveRoom_mm may give kShortMoveRoomShare of itself to the
// shift back (instead of half: the corner at its far end may take the other half), as a row's
// 0.5 mm steps turn by 1 degree at that end and need a few hundredths of a millimetre there.
// Measured on the bench programs (docs/benchmarks.md, "Row ends within P"): tp_default -2 ms,
// surface_3d at P0.001 -8 ms, nothing slower; half of the next line, or 0.9 of lines up to
// any length, left tp_default as it was or cost pocket_sharp 8 ms.
constexpr double kAxisShiftMinNormal = 0.9;
constexpr double kShortMoveRoom_mm = 1.0;
constexpr double kShortMoveRoomShare = 0.9;
// One-sided offset corners (one_sided_offset_corner): where one line has no room for a shift,
// only the other is moved outwards, by kOffsetShare of the tolerance; the turn is the parabola
// between that offset line and the other line as programmed. Up to 90 degrees its cut may be
// (sqrt(P + d) + sqrt(P))^2 / sin(angle) for a proof limit P (see there); the first cut tried
// is kOneSidedFirstShare of that (the turn is proved in two pieces split where it passes from
// one line to the other, which holds at once up to 0.998 on the bench programs), then
// kOneSidedShrink times less until every piece is proved, at most kOneSidedAttempts times.
// Turns up to about 120 degrees (cos >= kOneSidedMinCos): past 90 degrees the proofs decide.
constexpr double kOneSidedFirstShare = 0.995;
constexpr double kOneSidedShrink = 0.96;
constexpr int kOneSidedAttempts = 10;
constexpr double kOneSidedMinCos = -0.5;
// Offset corners with an arc (offset_arc_corner): a move's curvature moves the turn's deepest
// point, so the cut shrinks by this factor until every piece is proved, at most this many times.
constexpr double kOffsetArcShrink = 0.9;
constexpr int kOffsetArcAttempts = 8;
// They are tried only where both moves allow at least this many times the speed of the blend
// inside the corner. Below that they gain little and cost much: ex23's 28 arc-line corners at
// the 10 mm/s feed (1.13 x the inside blend's 8.85 mm/s) gained 11 ms in all as offset corners
// and halved its planning throughput (the proofs against an arc's chords split its pieces
// several times); tangent_arcs' arc-rapid corner (40 mm/s, 4.5 x) gains 23 ms.
constexpr double kOffsetArcMinGain = 1.25;
// With a jerk limit a Bezier blend (curvature steps at its ends) is used only if its ends can
// be passed at this share of the feed.
constexpr double kJerkBlendMinFeedShare = 0.25;

// The blend cut: what the geometry allows, shortened to what the corner speed needs, but not
// below kSpeedCutFloor of the former: near-collinear corners need almost no cut, and a blend a
// million times shorter than its coordinates gets second derivatives from rounding.
double cut_for_speed(double l_geom_mm, double l_speed_mm) {
    return std::min(l_geom_mm, std::max(l_speed_mm, kSpeedCutFloor * l_geom_mm));
}

bool finite_array(const AxisArray& a) {
    return std::all_of(a.begin(), a.end(), [](double x) { return std::isfinite(x); });
}

void validate_segment(const PathSegment& seg) {
    if (!finite_array(seg.end_mm)) throw PlanError(seg.line, "end point is not a finite number");
    if (!seg.rapid && !(seg.feed_mm_s > 0 && std::isfinite(seg.feed_mm_s)))
        throw PlanError(seg.line, "feed move needs a positive feed rate (got " +
                                      std::to_string(seg.feed_mm_s) + " mm/s)");
    if (seg.rapid && !(seg.rapid_mm_s >= 0 && std::isfinite(seg.rapid_mm_s)))
        throw PlanError(
            seg.line, "rapid rate must be >= 0 (got " + std::to_string(seg.rapid_mm_s) + " mm/s)");
    if (!(seg.tolerance_mm >= 0)) throw PlanError(seg.line, "blend tolerance must be >= 0");
    if (seg.kind == SegmentKind::Arc &&
        !(std::isfinite(seg.centre_mm[0]) && std::isfinite(seg.centre_mm[1])))
        throw PlanError(seg.line, "arc centre is not a finite number");
}

}  // namespace

void validate(const PlannerConfig& cfg) {
    for (int k = 0; k < kAxes; ++k) {
        if (!(cfg.limits.vel_mm_s[k] > 0) || !(cfg.limits.acc_mm_s2[k] > 0))
            throw std::invalid_argument("axis " + std::to_string(k) +
                                        ": velocity and acceleration limits must be > 0");
        if (!(cfg.limits.jerk_mm_s3[k] >= 0))
            throw std::invalid_argument("axis " + std::to_string(k) +
                                        ": jerk limit must be >= 0 (0 = unlimited)");
    }
    validate_joints(cfg.limits.joints);
    if (!(cfg.servo_period_s > 0)) throw std::invalid_argument("servo period must be > 0");
    for (double reserve : {cfg.override_reserve, cfg.override_reserve_no_jerk})
        if (!(reserve > 0 && cfg.junction_share >= 0 && reserve + cfg.junction_share < 1))
            throw std::invalid_argument(
                "override_reserve and override_reserve_no_jerk must be > 0 and each plus "
                "junction_share < 1");
    if (!(cfg.max_rate >= 1)) throw std::invalid_argument("max_rate must be >= 1");
    if (cfg.window < 2) throw std::invalid_argument("window must hold at least 2 elements");
}

double override_reserve_in_effect(const PlannerConfig& cfg) noexcept {
    return jerk_limited(cfg.limits) ? cfg.override_reserve : cfg.override_reserve_no_jerk;
}

Planner::Planner(const PlannerConfig& cfg, const AxisArray& start) : cfg_(cfg), last_end_(start) {
    validate(cfg_);
    jerk_mode_ = jerk_limited(cfg_.limits);
    reserve_ = override_reserve_in_effect(cfg_);
    items_.reserve(cfg_.window * 2);
    // At most one group per item (without a jerk limit exactly one): reserved like the items,
    // so that build_groups() does not reallocate them within a window (it grew them by
    // doubling from none, copying them each time, in every new planner).
    groups_.reserve(cfg_.window * 2);
    vj_.reserve(cfg_.window * 2 + 1);
    out_.reserve(cfg_.window * 2);
}

void Planner::reset(const AxisArray& start) {
    last_end_ = start;
    have_pending_ = false;
    items_.clear();
    groups_.clear();
    head_ = group_head_ = grouped_end_ = 0;
    v_start_ = 0;
    out_.clear();
    out_head_ = 0;
}

void Planner::push(const PathSegment& seg) {
    validate_segment(seg);
    // Built in place in the free slot (Piece is trivially destructible): nothing is cleared
    // first, and it need not be copied when it becomes the pending piece.
    Piece& next = *::new (static_cast<void*>(&pieces_[1 - pending_])) Piece{
        seg.kind == SegmentKind::Arc ? make_arc(last_end_, seg) : make_line(last_end_, seg.end_mm),
        seg.rapid ? seg.rapid_mm_s : seg.feed_mm_s,
        seg.rapid,
        seg.tolerance_mm,
        seg.exact_stop,
        seg.line,
        seg.move_id,
        0,
        false,
        !have_pending_,
    };
    if (next.geom.length_mm < kMinLength_mm) {
        if (have_pending_) pieces_[pending_].exact_stop |= seg.exact_stop;
        return;
    }
    last_end_ = seg.end_mm;
    if (have_pending_) close_piece(pieces_[pending_], &next);
    pending_ = 1 - pending_;
    have_pending_ = true;
    if (items_.size() - head_ >= cfg_.window) plan_and_emit(false);
}

void Planner::finish() {
    if (have_pending_) close_piece(pieces_[pending_], nullptr);
    have_pending_ = false;
    if (plan_and_emit(true) > 0) out_.back().rec().program_end = true;
    v_start_ = 0;
}

void Planner::classify(const Piece& p, const Piece& next, Junction& jn) const {
    if (p.exact_stop) return jn.set(0, false, 0);
    // p'' only for the curvature steps, which cost nothing without a jerk limit.
    EndDerivs pe = end_derivs(p.geom, jerk_mode_);
    EndDerivs ns = start_derivs(next.geom, jerk_mode_);
    AxisArray dt;
    double dmax = 0, dnorm2 = 0;
    for (int k = 0; k < kAxes; ++k) {
        dt[k] = ns.tangent[k] - pe.tangent[k];
        dmax = std::max(dmax, std::fabs(dt[k]));
        dnorm2 += dt[k] * dt[k];
    }
    const AxisLimits& lim = cfg_.limits;
    double curvature_cap = curvature_step_cap(pe.d2, ns.d2);
    if (dmax <= kTangentEps) return jn.set(curvature_cap, std::isfinite(curvature_cap), 0);
    // The blends' distance from the programmed path grows with sin(angle) (geometry.hpp); past
    // 90 degrees |T2 - T1| / sqrt(2) is used instead, so that a reversal does not spend half of
    // each move on a slow turn.
    double cos_angle = 1 - dnorm2 / 2;  // |T2 - T1|^2 = 2 - 2 cos(angle) for unit tangents
    double sin_angle =
        std::max(std::sqrt(std::max(0.0, 1 - cos_angle * cos_angle)), std::sqrt(dnorm2 / 2));
    double feed =
        std::min(p.feed_mm_s > 0 ? p.feed_mm_s : kInf, next.feed_mm_s > 0 ? next.feed_mm_s : kInf);
    if (!std::isfinite(feed)) feed = *std::max_element(lim.vel_mm_s.begin(), lim.vel_mm_s.end());
    // Without a jerk limit a blend cut longer than the corner speed needs buys nothing and
    // takes length from the moves, which speed up and slow down faster than a blend (and, when
    // one of them is a rapid, at the rapid's speed): cut only what passing at the speed either
    // move allows there (with a margin) needs. The parabola's cap is the model; the Bezier blends
    // with an arc turn a little harder, hence the margin. Between two lines of different feeds
    // the turn runs at the slower one whatever its cut, so it is cut for exactly that speed on
    // the share of the acceleration an offset corner's turn or an isolated parabola gets
    // (kIsolatedBlendCentripetal): 1.05 x on the default share made a 90 degree turn at
    // 10 mm/s 15 % longer (tp_default's G0 Y30 -> G1 Z0 F600). A parabola that will not be
    // isolated is cut for its own share below.
    const bool lines = p.geom.kind == ElementKind::Line && next.geom.kind == ElementKind::Line;
    const bool mixed = p.feed_mm_s != next.feed_mm_s;
    double l_speed_mm = kInf, speed_margin = 1, pass_mm_s = kInf;
    if (!jerk_mode_) {
        pass_mm_s = pass_speed_cap(pe.tangent, ns.tangent, lim,
                                   std::min(p.feed_mm_s > 0 ? p.feed_mm_s : kInf,
                                            next.feed_mm_s > 0 ? next.feed_mm_s : kInf));
        speed_margin = !mixed ? kCornerSpeedMargin : lines ? 1.0 : kMixedCornerSpeedMargin;
        l_speed_mm = parabola_cut_for_speed_mm(
            dt, speed_margin * pass_mm_s, lim,
            {1 - reserve_, 1 - reserve_, mixed && lines ? kIsolatedBlendCentripetal : 0.0});
    }
    if (lines && p.tolerance_mm > 0) {
        // Half of each line, and no more than the corner at p's start left of it (an offset
        // corner's shift back may take more than half of a short line).
        double l = std::min(std::min(p.geom.length_mm, next.geom.length_mm) / 2,
                            p.geom.length_mm - p.trim_start_mm);
        // A (near) reversal stops at its end point: the axis passes through zero speed there
        // anyway, so a blend saves almost nothing and would leave the bottom of a drilled
        // hole sqrt(2) tol short (the miss every turn past 90 degrees is allowed, see above).
        if (cos_angle < kReversalCos) return jn.set(0, false, 0);
        // Without a jerk limit the parabola (the per-axis bang-bang corner) is the fastest;
        // its distance from the lines is (l / 4) sin(angle) (geometry.hpp). When the
        // tolerance keeps it slower than the moves allow, the corner is cut on offset lines
        // instead if that fits (offset_corner).
        if (!jerk_mode_) {
            double l_tol = p.tolerance_mm / (kParabolaDeviationPerL * sin_angle);
            double l_geom = std::min(l, l_tol);
            if (l_speed_mm > l_tol && l > l_tol &&
                offset_corners(p, next, sin_angle, l_speed_mm, jn))
                return;
            l = cut_for_speed(l_geom, l_speed_mm);
            // close_piece gives a parabola kIsolatedBlendCentripetal only when both moves keep
            // at least its cut beside it; otherwise it turns on the default share.
            const bool isolated = p.geom.length_mm - p.trim_start_mm - l >= l &&
                                  next.geom.length_mm / 2 >= 2 * l;
            if (mixed && !isolated)
                l = cut_for_speed(l_geom, parabola_cut_for_speed_mm(
                                              dt, pass_mm_s, lim, {1 - reserve_, 1 - reserve_}));
            if (l > kMinLength_mm) return jn.set(kInf, false, l, Blend::Parabola);
        } else {
            l = std::min(l, p.tolerance_mm / (kBlendDeviationPerL * sin_angle));
            if (l > kMinLength_mm) return jn.set(kInf, false, l, Blend::Quartic);
        }
    }
    // A kink that is not blended: pass it only as fast as a velocity step of junction_share of
    // one servo period's acceleration (and jerk) allows. For real corners that speed is next
    // to nothing, and stopping outright spares both neighbours the junction share.
    // Several kinks can fall in one period when the moves between them are shorter than a
    // period's travel W = v max_rate period; their steps add up. A kink with a neighbour that
    // short (L: half the shorter neighbour, as blends at the far ends may trim them) takes
    // 1 / (2 + 2 W / L) of the share: in any window of length W the first such kink takes at
    // most 1/2 and each further one at most L / 2W, and the moves between them, each at least
    // its kinks' L long, fit in W, so the steps in one period add up to at most the share. A
    // kink whose neighbours are both longer than W shares its period with no other kink.
    double share = cfg_.junction_share, period = cfg_.servo_period_s;
    double near_mm = std::min(p.geom.length_mm, next.geom.length_mm) / 2;
    double travel_per_v = cfg_.max_rate * period;  // W / v
    double cap = kInf;
    // d: an axis's or joint's velocity step per unit of speed.
    auto kink = [&](double d, double acc, double jerk) {
        if (d <= kTangentEps) return;
        double step = share * acc * period;
        if (jerk > 0) step = std::min(step, share * jerk * period * period);
        double v = step / d;
        if (v * travel_per_v > near_mm) {  // 2 d v + 2 d (v travel_per_v / near) v = step
            double qa = 2 * d * travel_per_v / near_mm, qb = 2 * d;
            v = std::min(v, (-qb + std::sqrt(qb * qb + 4 * qa * step)) / (2 * qa));
        }
        cap = std::min(cap, v);
    };
    for (int k = 0; k < kAxes; ++k) kink(std::fabs(dt[k]), lim.acc_mm_s2[k], lim.jerk_mm_s3[k]);
    for (int j = 0; j < lim.joints.count; ++j)
        kink(std::fabs(joint_component(lim.joints, j, dt)), lim.joints.acc_mm_s2[j],
             lim.joints.jerk_mm_s3[j]);
    // Kinks with an arc (rounding in the program, or a real corner): a blend where passing
    // the kink would cost speed.
    if (cap < feed && p.tolerance_mm > 0 && sin_angle < kMaxArcBlendSin) {
        // As between two lines, the corner is cut on the moves carried outwards where the
        // blend inside it would be much slower than the moves allow (cut lengths grow with the
        // square of the speed; see kOffsetArcMinGain) and that fits.
        const double gain = kOffsetArcMinGain * speed_margin;
        if (!jerk_mode_ &&
            l_speed_mm > gain * gain * p.tolerance_mm / (kParabolaDeviationPerL * sin_angle) &&
            offset_arc_corner(p, next, sin_angle, l_speed_mm, jn))
            return;
        if (bezier_corner(p, next, sin_angle, feed, l_speed_mm, jn)) return;
    }
    if (cap < kKinkStopFraction * feed) return jn.set(0, false, 0);
    jn.set(std::min(cap, curvature_cap), true, 0);
}

double Planner::curvature_step_cap(const AxisArray& d2_before, const AxisArray& d2_after) const {
    // A step in curvature is a step in acceleration (v^2 times it); it matters only when jerk
    // is limited, and then it may be junction_share of one period's jerk.
    double cap = kInf;
    for (int k = 0; k < kAxes && jerk_mode_; ++k) {
        double step = std::fabs(d2_after[k] - d2_before[k]);
        if (step > 1e-12 && cfg_.limits.jerk_mm_s3[k] > 0)
            cap = std::min(cap, std::sqrt(cfg_.junction_share * cfg_.limits.jerk_mm_s3[k] *
                                          cfg_.servo_period_s / step));
    }
    const JointLimits& jl = cfg_.limits.joints;
    if (jl.count == 0 || !jerk_mode_) return cap;
    AxisArray d2_step;
    for (int k = 0; k < kAxes; ++k) d2_step[k] = d2_after[k] - d2_before[k];
    for (int j = 0; j < jl.count; ++j) {
        double step = std::fabs(joint_component(jl, j, d2_step));
        if (step > 1e-12 && jl.jerk_mm_s3[j] > 0)
            cap = std::min(cap, std::sqrt(cfg_.junction_share * jl.jerk_mm_s3[j] *
                                          cfg_.servo_period_s / step));
    }
    return cap;
}

namespace {

// Longest part of a move a corner blend may take: half of a line (the corner at its other end
// may take the other half), a little less of an arc so that an arc never vanishes between two
// blends.
double max_trim_mm(const Element& e, double trimmed_start_mm) {
    double left = e.length_mm - trimmed_start_mm;
    return e.kind == ElementKind::Line ? std::min(left, e.length_mm / 2)
                                       : std::min(left, e.length_mm * kMaxArcTrimShare);
}

// arc_end_mm: where an arc ends once trimmed, if already known (see trim_arc).
Element trimmed(const Element& e, double from_mm, double to_mm,
                const AxisArray* arc_end_mm = nullptr) {
    if (from_mm <= 0 && to_mm <= 0) return element_copy(e);  // `return e` copied with rep movs
    return e.kind == ElementKind::Line ? trim_line(e, from_mm, to_mm)
                                       : trim_arc(e, from_mm, to_mm, arc_end_mm);
}

}  // namespace

bool Planner::bezier_corner(const Piece& p, const Piece& next, double sin_angle, double feed_mm_s,
                            double l_speed_mm, Junction& jn) const {
    const double tol = p.tolerance_mm;
    double l_max = std::min(max_trim_mm(p.geom, p.trim_start_mm), max_trim_mm(next.geom, 0));
    // For two lines the parabola's distance from them is exactly (l / 4) sin(angle); with an
    // arc that is the first guess, checked and shrunk below.
    const double allowed_mm = kDeviationMargin * tol;
    double l = cut_for_speed(std::min(l_max, allowed_mm / (kParabolaDeviationPerL * sin_angle)),
                             l_speed_mm);
    const double L1 = p.geom.length_mm;
    double reach = std::min(l_max, kDeviationReach * l);
    const CornerPath path = corner_path(p.geom, reach, next.geom, reach, allowed_mm);
    struct Fit {
        CurvePoint a, b;  // the blend's ends on the moves
        BezierPoints ctrl;
    };
    auto fits = [&](double l_try, Fit& out) {
        const int order = jerk_mode_ ? 2 : 1;  // p'' only for the curvature steps
        evaluate_upto(p.geom, L1 - l_try, order, out.a);
        evaluate_upto(next.geom, l_try, order, out.b);
        return corner_bezier_within(out.a.p, out.a.d1, out.b.p, out.b.d1, l_try, path,
                                    allowed_mm, out.ctrl);
    };
    // Shrink until a cut is proved, first by only 3 % (with an arc the largest provable cut is
    // usually just under the two-line value: 0.974 of it on ex23's 90 degree arc-line corners),
    // then by 0.7; after a 0.7 step bisect back towards the cut that failed, as the corner speed
    // grows with the square root of the cut.
    // The cut proved last is tried[best]; a trial writes into the other one, which becomes best
    // when it is proved (copying a Fit, 864 bytes, was a rep movs).
    std::array<Fit, 2> tried;
    int best = 0;
    double l_fail = 0;  // a cut that was tried and not proved
    bool found = false;
    for (int attempt = 0; attempt < kBlendAttempts && l > kMinLength_mm; ++attempt) {
        if ((found = fits(l, tried[best]))) break;
        l_fail = l;
        l *= attempt == 0 ? kBlendFirstShrink : 0.7;
    }
    if (!found) return false;
    for (int i = 0; i < kBlendBisections && l_fail > l / kBlendFirstShrink * (1 + 1e-9); ++i) {
        double mid = std::sqrt(l * l_fail);
        if (fits(mid, tried[1 - best]))
            l = mid, best = 1 - best;
        else
            l_fail = mid;
    }
    const Fit& fit = tried[best];
    const CurvePoint &a = fit.a, &b = fit.b;
    jn.set(kInf, false, l, Blend::Curve);
    make_corner_bezier(fit.ctrl, path, jn.curve);
    jn.set_piece_axes(path);
    jn.curve_end_cap_mm_s = kInf;
    jn.curve_end_rough = false;
    if (!jerk_mode_) return true;  // without a jerk limit curvature steps cost nothing
    EndDerivs bs = start_derivs(jn.curve), be = end_derivs(jn.curve);
    jn.cap_mm_s = curvature_step_cap(a.d2, bs.d2);
    jn.rough = std::isfinite(jn.cap_mm_s);
    jn.curve_end_cap_mm_s = curvature_step_cap(be.d2, b.d2);
    jn.curve_end_rough = std::isfinite(jn.curve_end_cap_mm_s);
    // The steps make the neighbours give up the junction share: only worth it when the
    // corner can then be taken at a good part of the feed.
    if (std::min(jn.cap_mm_s, jn.curve_end_cap_mm_s) < kJerkBlendMinFeedShare * feed_mm_s)
        return false;
    return true;
}

// What an offset corner between the unit tangents t1 and t2 (turning by the angle whose cosine
// and sine are given, kept with it) asks of the axes: the outward normals n1, n2 off the
// incoming and the outgoing move (in their common plane); `turn`, the smallest
// A_k / |t2_k - t1_k|, which sets the turn's speed; `shift`, the largest |n_k| / A_k, which sets
// the lane changes' length. (Declared in planner.hpp: classify() makes it once for both kinds of
// offset corner between two lines.)
struct OffsetFrame {
    double cos_t, sin_t;
    AxisArray n1, n2;
    double turn = kInf, shift = 0;
};

namespace {

OffsetFrame offset_frame(const AxisArray& t1, const AxisArray& t2, double cos_t, double sin_t,
                         const AxisLimits& lim) {
    OffsetFrame f;
    f.cos_t = cos_t, f.sin_t = sin_t;
    // The axes' divisions first, with no branch, so that they are done two at a time (four
    // per axis, most of the frame's cost); then the smallest and largest, in axis order. A
    // turn of 0 in an axis gives acc / 0 = inf (acc > 0, validate()), which leaves the smallest
    // as it is, as a NaN does.
    AxisArray turn, shift;
    for (int k = 0; k < kAxes; ++k) {
        f.n1[k] = -(t2[k] - cos_t * t1[k]) / sin_t;
        f.n2[k] = (t1[k] - cos_t * t2[k]) / sin_t;
        turn[k] = lim.acc_mm_s2[k] / std::fabs(t2[k] - t1[k]);
        shift[k] = std::max(std::fabs(f.n1[k]), std::fabs(f.n2[k])) / lim.acc_mm_s2[k];
    }
    for (int k = 0; k < kAxes; ++k) {
        f.turn = std::min(f.turn, turn[k]);
        f.shift = std::max(f.shift, shift[k]);
    }
    if (lim.joints.count > 0) joint_turn_and_shift(t1, t2, f.n1, f.n2, lim.joints, f.turn, f.shift);
    return f;
}

// The first cut an offset corner tries: no longer than the parabola may be with its middle
// `share` tol inside the corner, nor than the speed both moves allow needs.
double offset_first_cut(double share, double tol, double sin_angle, double l_speed_mm) {
    return std::min(2 * share * tol / (kParabolaDeviationPerL * sin_angle),
                    std::max(l_speed_mm, kSpeedCutFloor * tol));
}

// The direction a lane change off or onto a line (unit tangent t, outward unit normal n) moves
// the tool by d: d times it lies d outwards, n itself unless n lies at least
// kAxisShiftMinNormal along an axis j and t has a part along j, then n + (t_j / n_j) t, which
// keeps the tool's motion along the other axes of the corner's plane as on the line (in two
// axes exactly: with t = (c, s), n = (-s, c), its first component is -s + (s / c) c = 0).
// `along` is t_j / n_j, how far it moves the tool along the line per unit outwards (0 for n).
struct LaneChange {
    AxisArray w;
    double along = 0;
};
LaneChange lane_change_direction(const AxisArray& t, const AxisArray& n) {
    int j = 0;
    for (int k = 1; k < kAxes; ++k)
        if (std::fabs(n[k]) > std::fabs(n[j])) j = k;
    LaneChange lc{n, 0};
    if (!(std::fabs(n[j]) >= kAxisShiftMinNormal) || t[j] == 0) return lc;
    lc.along = t[j] / n[j];
    for (int k = 0; k < kAxes; ++k) lc.w[k] = n[k] + lc.along * t[k];
    return lc;
}

// Room a line after a corner leaves for the shift back onto it (see kShortMoveRoom_mm): half
// of it, or kShortMoveRoomShare of a short one whose lane change runs along an axis.
double shift_back_room_mm(const Element& next, const AxisArray& n2) {
    double largest = 0;
    for (double x : n2) largest = std::max(largest, std::fabs(x));
    if (next.kind == ElementKind::Line && next.length_mm <= kShortMoveRoom_mm &&
        largest >= kAxisShiftMinNormal)
        return kShortMoveRoomShare * next.length_mm;
    return max_trim_mm(next, 0);
}

// An offset corner's cuts for a turn cut lp whose middle lies `share` tol inside the corner,
// between moves carried d outwards (only as far as that cut needs: each mm of offset lengthens
// the path by 2 tan(angle / 2)); `back` = d tan(angle / 2). The shifts are cut so that they
// pass at kShiftSpeedFactor times the turn's speed on kShiftCentripetal of the acceleration
// (a shift's sideways second derivative peaks at 6 d / ls^2), within the room the two moves
// leave them (room1 before the corner, room2 after); a much shorter shift caps the speed on the
// way into the corner and costs more than the corner gains, so then there are no cuts (false).
struct OffsetCuts {
    double d, back, ls1, ls2, before_mm, after_mm;
};

bool offset_cuts(double lp, double share, double tol, double sin_angle, double cos_t, double sin_t,
                 const OffsetFrame& f, double room1, double room2, OffsetCuts& c) {
    c.d = std::clamp(lp * kParabolaDeviationPerL * sin_angle - share * tol, kOffsetMinShare * tol,
                     share * tol);
    c.back = c.d * (1 - cos_t) / sin_t;
    if (!(lp > c.back)) return false;
    const double v_corner_mm_s = std::sqrt(2 * lp * f.turn);
    const double ls =
        kShiftSpeedFactor * v_corner_mm_s * std::sqrt(6 * c.d * f.shift / kShiftCentripetal);
    c.ls1 = std::min(ls, room1 - (lp - c.back));
    c.ls2 = std::min(ls, room2 - (lp - c.back));
    const double keep = kShiftMinSpeedFactor / kShiftSpeedFactor;
    if (c.ls1 < keep * ls || c.ls2 < keep * ls) return false;
    c.before_mm = lp - c.back + c.ls1, c.after_mm = lp - c.back + c.ls2;
    return true;
}

}  // namespace

// The offset corner (no jerk limit; two lines turning by up to about 90 degrees). The parabola
// alone cuts at most P inside the corner, but the tolerance also allows P outside it. So the
// tool shifts d <= P outwards off the incoming line (a cubic lane change, shift_out), turns on
// the parabola between the two lines moved d outwards, which may cut d + P deep, and shifts
// back onto the outgoing line (shift_back). For a turn from +X onto +Y at the origin: the tool
// leaves y = 0 for y = -d (shift_out), turns on the parabola from (d - l, -d) to (d, l - d)
// (control point the offset corner c2 = (d, -d)), whose middle (d - l / 4, l / 4 - d) =
// (-0.99 P, 0.99 P) for d = 0.99 P, l = 8 x 0.99 P, lies inside the corner, and returns from
// x = d to x = 0 (shift_back). It never enters the quadrant x > 0, y < 0 beyond the corner.
//
// Twice the cut turns sqrt(2) faster (90 degrees at P0.01, 1000 mm/s^2: 12.5 instead of
// 8.85 mm/s): each axis then passes the corner at sqrt(4 A P), the most the tolerance band
// allows (docs/benchmarks.md, the acceleration-aware bound). The path is 2 d tan(angle / 2)
// longer, the shifts need room on both lines, and each piece is proved within the tolerance
// (bezier_within against the programmed lines); otherwise the caller uses the parabola.
bool Planner::offset_corners(const Piece& p, const Piece& next, double sin_angle, double l_speed_mm,
                             Junction& jn) const {
    const AxisArray &t1 = p.geom.a, &t2 = next.geom.a;
    double cos_t = 0;
    for (int k = 0; k < kAxes; ++k) cos_t += t1[k] * t2[k];
    if (cos_t < kOneSidedMinCos) return false;
    const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
    const OffsetFrame f = offset_frame(t1, t2, cos_t, sin_t, cfg_.limits);
    return offset_corner(p, next, f, sin_angle, l_speed_mm, jn) ||
           one_sided_offset_corner(p, next, f, sin_angle, l_speed_mm, jn);
}

bool Planner::offset_corner(const Piece& p, const Piece& next, const OffsetFrame& f,
                            double sin_angle, double l_speed_mm, Junction& jn) const {
    const AxisArray &t1 = p.geom.a, &t2 = next.geom.a, &c = p.geom.end;
    const double cos_t = f.cos_t, sin_t = f.sin_t;
    if (cos_t < kOffsetMinCos) return false;
    const double tol = p.tolerance_mm;
    // The parabola may now lie up to d + kOffsetShare tol from the offset lines. Room for the
    // shifts: what the first line has left after the corner at its start (known by now), half
    // of the second (the corner at its end may take the other half), more of a short one
    // (shift_back_room_mm).
    const AxisArray &n1 = f.n1, &n2 = f.n2;
    const double lp = offset_first_cut(kOffsetShare, tol, sin_angle, l_speed_mm);
    const double room1 = p.geom.length_mm - p.trim_start_mm;
    const double room2 = shift_back_room_mm(next.geom, n2);
    OffsetCuts cuts;
    if (!offset_cuts(lp, kOffsetShare, tol, sin_angle, cos_t, sin_t, f, room1, room2, cuts))
        return false;
    const double d = cuts.d;
    // Each shift moves the tool d outwards along lane_change_direction, which may also move it
    // along the line: its end on the programmed line moves by that much, and the room it may
    // take is measured from there (the cuts again, with the same d).
    const LaneChange lc1 = lane_change_direction(t1, n1), lc2 = lane_change_direction(t2, n2);
    const AxisArray &w1 = lc1.w, &w2 = lc2.w;
    const double along1 = d * lc1.along, along2 = d * lc2.along;
    if ((along1 != 0 || along2 != 0) &&
        !offset_cuts(lp, kOffsetShare, tol, sin_angle, cos_t, sin_t, f, room1 - along1,
                     room2 + along2, cuts))
        return false;
    const double ls1 = cuts.ls1 + along1, ls2 = cuts.ls2 - along2;
    const double cut_before_mm = cuts.before_mm + along1, cut_after_mm = cuts.after_mm - along2;
    if (!(ls1 > 0 && ls2 > 0)) return false;
    // The offset corner c2 is d from both lines, outwards; a0 and b3 lie on the programmed lines.
    AxisArray c2, a0, a3, b0, b3;
    for (int k = 0; k < kAxes; ++k) {
        c2[k] = c[k] + d * (t1[k] - t2[k]) / sin_t;
        a3[k] = c2[k] - lp * t1[k];
        a0[k] = a3[k] - cuts.ls1 * t1[k] - d * w1[k];
        b0[k] = c2[k] + lp * t2[k];
        b3[k] = b0[k] + cuts.ls2 * t2[k] - d * w2[k];
    }
    // Every piece is proved within the tolerance of the programmed lines. In the axes neither
    // line moves, all their points equal the corner's (the terms added to it there are +-0), so
    // the proofs run in the lines' axes (shift_bezier_within, corner_piece_within). The
    // parabola's points are make_parabola(c2, t1, t2, lp)'s.
    const CornerPath path = corner_path(p.geom, cut_before_mm, next.geom, cut_after_mm, tol);
    const double limit = kOffsetProofShare * tol;
    BezierPoints out, par, in;
    // The lane changes' control legs are those of a shift of length ls along the normal (with
    // the legs of the corrected length tp_default took 2 ms longer).
    if (!shift_bezier_within(a0, t1, a3, t1, cuts.ls1 / 2, path, limit, out) ||
        !shift_bezier_within(b0, t2, b3, t2, cuts.ls2 / 2, path, limit, in))
        return false;
    for (int k = 0; k < kAxes; ++k) {
        par.p0[k] = c2[k] - lp * t1[k];
        par.p3[k] = c2[k] + lp * t2[k];
        par.p1[k] = par.p0[k] + 2 * lp / 3 * t1[k];
        par.p2[k] = par.p3[k] - 2 * lp / 3 * t2[k];
    }
    if (!corner_piece_within(par, path, limit)) return false;
    jn.set(kInf, false, cut_before_mm, Blend::Offset);
    jn.cut_after_mm = cut_after_mm;
    jn.has_shift_out = jn.has_shift_back = true;
    make_corner_bezier(out, path, jn.shift_out);
    make_corner_bezier(par, path, jn.curve);
    make_corner_bezier(in, path, jn.shift_back);
    jn.set_piece_axes(path);
    return true;
}

namespace {

// A stretch of path for local_time_s: its length, speed cap and tangential acceleration (no
// jerk limit).
struct Stretch {
    double length_mm, vcap_mm_s, acc_mm_s2;
};

// std::sqrt(x2) where x2 may be x * x for the x >= 0 it was made from, unchanged: then that
// root is x itself, and taking it (a long-latency instruction on the estimate's critical path)
// is skipped. In binary floating point with rounding to nearest the square root of the rounded
// x * x is x exactly unless the square overflows or underflows (S. Boldo, "Stupid is as stupid
// does: taking the square root of the square of a floating-point number", 2015; also checked
// here on 3e8 random x over the range below): the same value either way.
double root_of_square(double x2, double x) {
    constexpr double kLow = 0x1p-500, kHigh = 0x1p+500;  // x * x stays a normal number
    if (x2 == x * x && x >= kLow && x <= kHigh) return x;
    return std::sqrt(x2);
}

// Time to run the stretches in turn, entering at v_in_mm_s and leaving at v_out_mm_s (or as
// fast as the caps allow there), each at the fastest trapezoid the junction speeds leave it:
// the planner's passes (plan_and_emit) on a few elements, to compare two ways of cutting one
// corner.
template <std::size_t N>
double local_time_s(const std::array<Stretch, N>& st, double v_in_mm_s, double v_out_mm_s) {
    // Junction speeds squared: the passes need no roots. x: each one before the passes, whose
    // root need not be taken where they leave its square as it was.
    std::array<double, N + 1> x, v2;
    auto sq = [](double y) { return y * y; };
    x[0] = std::min(v_in_mm_s, st[0].vcap_mm_s);
    x[N] = std::min(v_out_mm_s, st[N - 1].vcap_mm_s);
    for (std::size_t i = 1; i < N; ++i) x[i] = std::min(st[i - 1].vcap_mm_s, st[i].vcap_mm_s);
    for (std::size_t i = 0; i <= N; ++i) v2[i] = sq(x[i]);
    for (std::size_t i = N; i-- > 0;)
        v2[i] = std::min(v2[i], v2[i + 1] + 2 * st[i].acc_mm_s2 * st[i].length_mm);
    for (std::size_t i = 0; i < N; ++i)
        v2[i + 1] = std::min(v2[i + 1], v2[i] + 2 * st[i].acc_mm_s2 * st[i].length_mm);
    std::array<double, N + 1> v;  // each junction's speed, once
    for (std::size_t i = 0; i <= N; ++i) v[i] = root_of_square(v2[i], x[i]);
    double t = 0;
    for (std::size_t i = 0; i < N; ++i) {
        const double a = st[i].acc_mm_s2, len = st[i].length_mm;
        const double peak2 = std::min(sq(st[i].vcap_mm_s), (2 * a * len + v2[i] + v2[i + 1]) / 2);
        const double peak = root_of_square(peak2, st[i].vcap_mm_s);
        const double ramps_mm = (2 * peak2 - v2[i] - v2[i + 1]) / (2 * a);
        t += (2 * peak - v[i] - v[i + 1]) / a + std::max(0.0, len - ramps_mm) / peak;
    }
    return t;
}

// A line along the unit tangent t at `feed` (<= 0: none) on acc_share of each axis's and
// listed joint's acceleration, as element_limits gives it (|p'| = |t|, p'' = 0), for x_mm of
// it.
Stretch line_stretch(const AxisArray& t, double x_mm, double feed, const AxisLimits& lim,
                     double acc_share) {
    Stretch st{x_mm, feed > 0 ? feed : kInf, kInf};
    auto limit = [&](double g1, double vel, double acc) {
        if (g1 == 0) return;
        st.vcap_mm_s = std::min(st.vcap_mm_s, vel / g1);
        st.acc_mm_s2 = std::min(st.acc_mm_s2, acc_share * acc / g1);
    };
    for (int k = 0; k < kAxes; ++k) limit(std::fabs(t[k]), lim.vel_mm_s[k], lim.acc_mm_s2[k]);
    const JointLimits& jl = lim.joints;
    for (int j = 0; j < jl.count; ++j)
        limit(std::fabs(joint_component(jl, j, t)), jl.vel_mm_s[j], jl.acc_mm_s2[j]);
    return st;
}

// bounds(make_parabola(c, t1, t2, l)) without making it, for any cut l: its hodograph runs
// straight from t1 to t2 (|p'_k| <= max(|t1_k|, |t2_k|)) and p'' = (t2 - t1) / 2l throughout.
// Only p'' depends on l, and only in the listed axes (the others have t1_k = t2_k = +-0 there,
// and so p'' = +0 whatever l): the rest is made once per corner (make_parabola_bounds), p'' for
// each cut (at, in place: a copy of the 400 bytes per cut was 8 % of the corner's own time).
struct ParabolaBounds {
    ElementBounds b;
    AxisArray turn;  // |t2 - t1|

    const ElementBounds& at(double l_mm) {
        for (int i = 0; i < b.axis_count; ++i) {
            const int k = b.axes[i];
            b.g2[k] = turn[k] / (2 * l_mm);
        }
        return b;
    }
};

// The axes listed are those with max(|t1_k|, |t2_k|) > 0: a turn |t2_k - t1_k| > 0 implies it
// (unit tangents of lines, finite), so listing those with p' or p'' nonzero lists the same.
ParabolaBounds make_parabola_bounds(const AxisArray& t1, const AxisArray& t2) {
    ParabolaBounds pb;
    ElementBounds& b = pb.b;
    // The zeros as whole arrays: stored in the loop they became one rep stos, whose start-up
    // cost more than the stores.
    b.g2 = {};
    b.g3 = {};
    b.tangential_in_plane = {};
    int n = 0;
    for (int k = 0; k < kAxes; ++k) {
        b.g1[k] = b.linear[k] = std::max(std::fabs(t1[k]), std::fabs(t2[k]));
        pb.turn[k] = std::fabs(t2[k] - t1[k]);
        if (b.g1[k] > 0) b.axes[n++] = static_cast<std::uint8_t>(k);
    }
    b.axis_count = n;
    return pb;
}

// Proved as corner_piece_within, in two pieces split at the parameter u (de Casteljau): a
// parabola that lies near one line up to u and near the other after it is proved at once
// (each piece's hull near one chord as a whole, corner_part_within), where halving it would
// split down to the depth limit around u.
bool split_piece_within(const BezierPoints& b, double u, const CornerPath& path, double limit_mm) {
    // On a path at rest the proofs read the path's axes only (corner_part_within): the halves
    // are split there alone, else in every axis.
    BezierPoints first, second;
    const bool at_rest = path.still_at_rest;
    const int n = at_rest ? path.dims : kAxes;
    for (int j = 0; j < n; ++j) {
        const int k = at_rest ? path.axes[j] : j;
        const double p01 = b.p0[k] + u * (b.p1[k] - b.p0[k]);
        const double p12 = b.p1[k] + u * (b.p2[k] - b.p1[k]);
        const double p23 = b.p2[k] + u * (b.p3[k] - b.p2[k]);
        const double q0 = p01 + u * (p12 - p01), q1 = p12 + u * (p23 - p12);
        const double m = q0 + u * (q1 - q0);
        first.p0[k] = b.p0[k], first.p1[k] = p01, first.p2[k] = q0, first.p3[k] = m;
        second.p0[k] = m, second.p1[k] = q1, second.p2[k] = p23, second.p3[k] = b.p3[k];
    }
    return corner_part_within(first, path, limit_mm) && corner_part_within(second, path, limit_mm);
}

}  // namespace

// The one-sided offset corner (no jerk limit; two lines): where a line is too short for the
// lane change offset_corner needs (a 0.5 mm step next to a row turn on tp_default), only the
// other line is moved outwards by d, and the parabola turns between the moved line and the
// other one as programmed: the shift lies on the long line, the short one keeps only the
// parabola's cut. For a turn from +X onto +Y at the origin, with the line before it moved:
// the offset line y = -d meets the line x = 0 at c2 = (0, -d); the parabola runs from
// (-lp, -d) to (0, lp - d) with control point c2. In general the two offset lines, moved d1
// along n1 and d2 along n2 (one of them 0), meet at c2 = c + d1 n1 + a t1 with
// a = (d2 - d1 cos) / sin, which lies b = (d2 cos - d1) / sin along t2 from c (n1.t1 = 0,
// n2.t1 = sin, n1.n2 = cos, n1.t2 = -sin). Every piece is proved within kOffsetProofShare of
// the tolerance of the programmed lines (bezier_within); the cut shrinks until that holds, and
// below the inside parabola's cut (no gain) the caller uses that parabola.
bool Planner::one_sided_offset_corner(const Piece& p, const Piece& next, const OffsetFrame& f,
                                      double sin_angle, double l_speed_mm, Junction& jn) const {
    const AxisArray &t1 = p.geom.a, &t2 = next.geom.a, &c = p.geom.end;
    const double cos_t = f.cos_t, sin_t = f.sin_t;
    if (!(sin_t > 0)) return false;
    const double tol = p.tolerance_mm;
    const double room1 = p.geom.length_mm - p.trim_start_mm, room2 = max_trim_mm(next.geom, 0);
    const double l_inside = tol / (kParabolaDeviationPerL * sin_angle);
    const double d = kOffsetShare * tol;
    const double keep = kShiftMinSpeedFactor / kShiftSpeedFactor;
    const double limit = kOffsetProofShare * tol;
    // The side with more room takes the shift (the other would have failed offset_corner).
    const bool shift_before = room1 >= room2;
    const double d1 = shift_before ? d : 0, d2 = shift_before ? 0 : d;
    const double a = (d2 - d1 * cos_t) / sin_t, b = (d2 * cos_t - d1) / sin_t;
    // It is used only where it is faster than the parabola inside the corner (classify) by
    // the estimate local_time_s: its shift keeps part of the acceleration for turning (most
    // where the shifted line is not along an axis), and the turn is longer.
    // The lines run on for X1, X2 beyond the longest cuts, as far as ramping from the speed
    // both allow takes: the estimate is the time from X1 before to X2 after the corner.
    const double share = 1 - reserve_;
    const double f1 = p.feed_mm_s, f2 = next.feed_mm_s;
    const double turn_feed = f1 > 0 && f2 > 0 ? std::min(f1, f2) : std::max(f1, f2);
    // A parabola cut l (the turn), on `centripetal` of the acceleration. Without joints
    // element_limits reads only the element's kind (arc or not) besides the bounds, and the
    // line p stands in for it (making one clears and fills 400 bytes a call); the joints' bounds
    // it takes from the element itself (any parabola of that cut: they depend on its shape).
    const LimitShares shares{share, share, 0};
    ParabolaBounds parabola_bounds = make_parabola_bounds(t1, t2);
    auto parabola = [&](double l, double centripetal) {
        const ElementBounds& b = parabola_bounds.at(l);
        LimitShares turning = shares;
        turning.blend_centripetal = centripetal;
        const ElementLimits lim =
            cfg_.limits.joints.count > 0
                ? element_limits(make_parabola(c, t1, t2, l), b, cfg_.limits, turn_feed, turning)
                : element_limits(p.geom, b, cfg_.limits, turn_feed, turning);
        return Stretch{2 * l, lim.vcap_mm_s, lim.tangent.acc_mm_s2};
    };
    const Stretch far1 = line_stretch(t1, 0, f1, cfg_.limits, share);
    const Stretch far2 = line_stretch(t2, 0, f2, cfg_.limits, share);
    const double v_ends = std::min(far1.vcap_mm_s, far2.vcap_mm_s);
    // A line that starts at rest (the program's first move, or after a stop) is entered at
    // rest where it starts.
    const double v_in = p.start_at_rest ? 0 : v_ends;
    const double x1 = room1 + (p.start_at_rest ? 0 : v_ends * v_ends / (2 * far1.acc_mm_s2));
    const double x2 = room2 + v_ends * v_ends / (2 * far2.acc_mm_s2);
    auto line1 = [&](double cut_mm) {
        return Stretch{x1 - cut_mm, far1.vcap_mm_s, far1.acc_mm_s2};
    };
    auto line2 = [&](double cut_mm) {
        return Stretch{x2 - cut_mm, far2.vcap_mm_s, far2.acc_mm_s2};
    };
    // The parabola classify() would use, with close_piece's turning share.
    const double l_par = cut_for_speed(
        std::min(std::min(p.geom.length_mm, next.geom.length_mm) / 2, l_inside), l_speed_mm);
    const bool isolated = room1 - l_par >= l_par && next.geom.length_mm / 2 >= 2 * l_par;
    const Stretch inside = parabola(l_par, isolated ? kIsolatedBlendCentripetal : 0);
    const double t_inside =
        local_time_s(std::array<Stretch, 3>{line1(l_par), inside, line2(l_par)}, v_in, v_ends);
    // The parabola from c2 - lp t1 to c2 + lp t2 (c2 on the programmed second line) is
    // lp (1 - u)^2 sin from the second line and |lp u^2 sin - d| from the first: the smaller
    // is largest where they are equal, within `limit` for lp sin up to
    // (sqrt(limit + d) + sqrt(limit))^2 (the 90 degree case worked out in
    // RightAngleOntoAShortLineIsCutOnTheLongLineMovedOutwards); the same with the lines'
    // roles swapped.
    const double deepest = std::sqrt(limit + d) + std::sqrt(limit);
    double lp = std::min(kOneSidedFirstShare * deepest * deepest / sin_t,
                         std::max(l_speed_mm, kSpeedCutFloor * tol));
    for (int attempt = 0; attempt < kOneSidedAttempts && lp > l_inside;
         ++attempt, lp *= kOneSidedShrink) {
        if (!(lp > a && lp + b > 0)) continue;
        // The shift passes at kShiftSpeedFactor times the turn's speed, as in offset_cuts, and
        // takes the room its line leaves after the turn's cut.
        const double v_corner_mm_s = std::sqrt(2 * lp * f.turn);
        const double ls_full =
            kShiftSpeedFactor * v_corner_mm_s * std::sqrt(6 * d * f.shift / kShiftCentripetal);
        const double on1 = lp - a, on2 = lp + b;  // the turn's cut on each line
        const double ls = std::min(ls_full, (shift_before ? room1 - on1 : room2 - on2));
        if (ls < keep * ls_full || (shift_before ? on2 > room2 : on1 > room1)) continue;
        const double before_mm = on1 + (shift_before ? ls : 0);
        const double after_mm = on2 + (shift_before ? 0 : ls);
        AxisArray c2;
        BezierPoints par, shift;
        for (int k = 0; k < kAxes; ++k) {
            c2[k] = c[k] + d1 * f.n1[k] + a * t1[k];
            par.p0[k] = c2[k] - lp * t1[k];
            par.p3[k] = c2[k] + lp * t2[k];
            par.p1[k] = par.p0[k] + 2 * lp / 3 * t1[k];
            par.p2[k] = par.p3[k] - 2 * lp / 3 * t2[k];
        }
        // The parabola is nearer the moved line before u (where u^2 lp sin - d1 = (1 - u)^2 lp
        // sin - d2 for the distances from the moved lines) and the other one after it.
        const double u_cross = std::clamp((1 + (d1 - d2) / (lp * sin_t)) / 2, 0.0625, 0.9375);
        const CornerPath path = corner_path(p.geom, before_mm, next.geom, after_mm, tol);
        if (!split_piece_within(par, u_cross, path, limit)) continue;
        if (shift_before) {
            AxisArray a0;
            for (int k = 0; k < kAxes; ++k) a0[k] = par.p0[k] - ls * t1[k] - d1 * f.n1[k];
            if (!shift_bezier_within(a0, t1, par.p0, t1, ls / 2, path, limit, shift)) continue;
        } else {
            AxisArray b3;
            for (int k = 0; k < kAxes; ++k) b3[k] = par.p3[k] + ls * t2[k] - d2 * f.n2[k];
            if (!shift_bezier_within(par.p3, t2, b3, t2, ls / 2, path, limit, shift)) continue;
        }
        Element& shift_e = shift_before ? jn.shift_out : jn.shift_back;
        make_corner_bezier(shift, path, shift_e);
        // The shift's bounds and limits as add_item() makes them for its Item (bounds(e,
        // moving) on the axes set_piece_axes() lists: the values bounds(e) gives), kept for
        // close_piece().
        const std::span<const int> moving =
            path.still_at_rest ? std::span<const int>(path.axes.data(), path.dims)
                               : std::span<const int>();
        // Written in place: assigning bounds()'s value copied it once more (rep movs).
        if (moving.empty())
            jn.shift_bounds = bounds(shift_e);
        else
            bounds_into(shift_e, moving, jn.shift_bounds);
        jn.shift_lim = element_limits(shift_e, jn.shift_bounds, cfg_.limits,
                                      shift_before ? f1 : f2, {share, share, kShiftCentripetal});
        const ElementLimits& shift_lim = jn.shift_lim;
        const Stretch shifted{shift_e.length_mm, shift_lim.vcap_mm_s, shift_lim.tangent.acc_mm_s2};
        const Stretch turn = parabola(lp, kIsolatedBlendCentripetal);
        const double t_one_sided = local_time_s(
            shift_before ? std::array<Stretch, 4>{line1(before_mm), shifted, turn, line2(after_mm)}
                         : std::array<Stretch, 4>{line1(before_mm), turn, shifted, line2(after_mm)},
            v_in, v_ends);
        if (!(t_one_sided < t_inside)) return false;
        make_corner_bezier(par, path, jn.curve);
        jn.set(kInf, false, before_mm, Blend::Offset);
        jn.cut_after_mm = after_mm;
        jn.has_shift_out = shift_before;
        jn.has_shift_back = !shift_before;
        jn.set_piece_axes(path);
        return true;
    }
    return false;
}

namespace {

// A move carried a distance d along a direction n that turns with it (n is given at one end of
// the move and is perpendicular to its tangent there): a line becomes the line moved by d n; on
// an arc or helix the part of n in the arc's plane turns with the arc and the rest stays, so the
// point at s is p(s) + d N(s) with |N(s)| = |n|, exactly d from the move's point at the same s,
// and the carried curve is again a circle or helix about the same axis.
class CarriedMove {
  public:
    CarriedMove(const Element& e, double s_ref_mm, const AxisArray& n, double d_mm)
        : e_(e), d_(d_mm), rest_(n) {
        if (e.kind != ElementKind::Arc) return;
        AxisArray radial, tang;
        frame(s_ref_mm, radial, tang);
        for (int k = 0; k < kAxes; ++k) radial_ += n[k] * radial[k], tangential_ += n[k] * tang[k];
        for (int k = 0; k < kAxes; ++k) rest_[k] -= radial_ * radial[k] + tangential_ * tang[k];
    }

    // The carried curve's point and unit tangent at the move's s.
    void at(double s_mm, AxisArray& p, AxisArray& t) const {
        CurvePoint cp;
        evaluate_upto(e_, s_mm, 1, cp);
        if (e_.kind != ElementKind::Arc) {
            for (int k = 0; k < kAxes; ++k) p[k] = cp.p[k] + d_ * rest_[k];
            t = cp.d1;
            return;
        }
        AxisArray radial, tang;
        frame(s_mm, radial, tang);
        const double k1 = e_.sweep_rad / e_.length_mm;
        double norm2 = 0;
        for (int k = 0; k < kAxes; ++k) {
            p[k] = cp.p[k] + d_ * (radial_ * radial[k] + tangential_ * tang[k] + rest_[k]);
            t[k] = cp.d1[k] + d_ * k1 * (radial_ * tang[k] - tangential_ * radial[k]);
            norm2 += t[k] * t[k];
        }
        const double inv = 1 / std::sqrt(norm2);
        for (double& x : t) x *= inv;
    }

  private:
    // The arc's unit radial and counter-clockwise tangent in its plane at s.
    void frame(double s_mm, AxisArray& radial, AxisArray& tang) const {
        const double th = e_.theta0_rad + e_.sweep_rad * std::clamp(s_mm / e_.length_mm, 0.0, 1.0);
        const double cs = std::cos(th), sn = std::sin(th);
        for (int k = 0; k < kAxes; ++k) {
            radial[k] = cs * e_.a[k] + sn * e_.b[k];
            tang[k] = -sn * e_.a[k] + cs * e_.b[k];
        }
    }

    const Element& e_;
    double d_;
    double radial_ = 0, tangential_ = 0;  // arcs: n's parts along the radial and the tangent
    AxisArray rest_;                      // the part of n that does not turn
};

// A shift between `move` and its carried copy (offset_arc_corner), proved as corner_bezier_within
// would. Off or onto a line the shift lies along the line's one chord: shift_bezier_within skips
// the proof by halves when the whole hull lies well within reach of it. Along an arc it spans several of the
// arc's chords, so the whole-hull check fails and would only add work (measured: 0.1 % more
// instructions on tangent_arcs; its rounding argument holds for any chord, arcs' included).
bool lane_change_within(const Element& move, const AxisArray& p0, const AxisArray& t1,
                        const AxisArray& p3, const AxisArray& t2, double l_mm,
                        const CornerPath& path, double limit_mm, BezierPoints& out) {
    return move.kind == ElementKind::Line
               ? shift_bezier_within(p0, t1, p3, t2, l_mm, path, limit_mm, out)
               : corner_bezier_within(p0, t1, p3, t2, l_mm, path, limit_mm, out);
}

}  // namespace

// The offset corner where one or both moves are arcs or helices (no jerk limit). As between two
// lines (offset_corner), the tool shifts d outwards off the incoming move, turns between the two
// moves carried d outwards, and shifts back onto the outgoing move; here "carried outwards"
// keeps the moves' curvature (CarriedMove), so a shift along an arc stays d from it. The corner
// frame (the outward normals n1 and n2, the cut lp and the offset d) is the two lines' one for
// the moves' tangents at the corner; the turn is the corner Bezier between the carried moves
// (the parabola when both are lines) and each shift the cubic lane change between a move and
// its carried copy, with the tangents of the curves they join. A move's curvature moves the
// turn's deepest point, so the proofs decide (each piece within kOffsetProofShare of the
// tolerance of the programmed moves, bezier_within); on failure the cut shrinks, and once it is
// no longer than the one the Bezier blend inside the corner may take, the caller uses that.
bool Planner::offset_arc_corner(const Piece& p, const Piece& next, double sin_angle,
                                double l_speed_mm, Junction& jn) const {
    const EndDerivs pe = end_derivs(p.geom, false), ns = start_derivs(next.geom, false);
    const AxisArray &t1 = pe.tangent, &t2 = ns.tangent;
    double cos_t = 0;
    for (int k = 0; k < kAxes; ++k) cos_t += t1[k] * t2[k];
    if (cos_t < kOffsetMinCos) return false;
    const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
    const double tol = p.tolerance_mm;
    // A carried arc keeps at least half its radius (d <= tol).
    for (const Element* e : {&p.geom, &next.geom})
        if (e->kind == ElementKind::Arc && !(e->radius_mm > 2 * tol)) return false;
    const OffsetFrame f = offset_frame(t1, t2, cos_t, sin_t, cfg_.limits);
    const AxisArray &n1 = f.n1, &n2 = f.n2;
    // Room for the shifts: a line before the corner may give all it has left after the corner
    // at its start, an arc kMaxArcTrimShare of itself; the move after, what max_trim_mm allows.
    const double L1 = p.geom.length_mm;
    const double room1 = p.geom.kind == ElementKind::Line ? L1 - p.trim_start_mm
                                                          : max_trim_mm(p.geom, p.trim_start_mm);
    const double room2 = max_trim_mm(next.geom, 0);
    // The Bezier blend inside the corner may cut this much: a shorter offset cut gains nothing.
    const double l_inside = tol / (kParabolaDeviationPerL * sin_angle);
    auto cuts_for = [&](double lp, double share, OffsetCuts& c) {
        return offset_cuts(lp, share, tol, sin_angle, cos_t, sin_t, f, room1, room2, c);
    };
    auto first_cut = [&](double share) {
        return offset_first_cut(share, tol, sin_angle, l_speed_mm);
    };
    // The path is cut into chords once, for the longest cuts tried; an arc's chords leave a
    // slack (the arc's distance from them) that the shift and the turn must keep clear of, so
    // both use that much less of the tolerance.
    OffsetCuts c;
    if (!cuts_for(first_cut(kOffsetShare), kOffsetShare, c)) return false;
    const CornerPath path = corner_path(p.geom, c.before_mm, next.geom, c.after_mm, tol);
    double slack_mm = 0;
    for (int i = 0; i < path.count; ++i) slack_mm = std::max(slack_mm, path.slack_mm[i]);
    const double share = kOffsetShare - slack_mm / tol;
    const double limit = kOffsetProofShare * tol;
    double lp = first_cut(share);
    for (int attempt = 0; attempt < kOffsetArcAttempts && lp > l_inside;
         ++attempt, lp *= kOffsetArcShrink) {
        if (!cuts_for(lp, share, c)) continue;
        const CarriedMove q1(p.geom, L1, n1, c.d), q2(next.geom, 0, n2, c.d);
        CurvePoint a0, b3;
        evaluate_upto(p.geom, L1 - c.before_mm, 1, a0);
        evaluate_upto(next.geom, c.after_mm, 1, b3);
        AxisArray a3, ta3, b0, tb0;
        q1.at(L1 - (lp - c.back), a3, ta3);
        q2.at(lp - c.back, b0, tb0);
        BezierPoints out, bend, in;
        if (!corner_bezier_within(a3, ta3, b0, tb0, lp, path, limit, bend) ||
            !lane_change_within(p.geom, a0.p, a0.d1, a3, ta3, c.ls1 / 2, path, limit, out) ||
            !lane_change_within(next.geom, b0, tb0, b3.p, b3.d1, c.ls2 / 2, path, limit, in))
            continue;
        jn.set(kInf, false, c.before_mm, Blend::Offset);
        jn.cut_after_mm = c.after_mm;
        jn.has_shift_out = jn.has_shift_back = true;
        make_corner_bezier(out, path, jn.shift_out);
        make_corner_bezier(bend, path, jn.curve);
        make_corner_bezier(in, path, jn.shift_back);
        jn.set_piece_axes(path);
        return true;
    }
    return false;
}

template <class MakeElement>
double Planner::add_item_made(MakeElement&& make, double feed, double end_cap, bool rough,
                              const Piece& owner, bool rapid) {
    Item& it = items_.emplace_back(Item::Made{}, std::forward<MakeElement>(make));
    const double length_mm = it.geom.length_mm;
    if (length_mm > kMinLength_mm)
        set_item_limits(it, feed, end_cap, rough, owner, rapid, 0);
    else
        items_.pop_back();  // vanished (its bounds were made for nothing; rare)
    return length_mm;
}

void Planner::close_piece(Piece& p, Piece* next) {
    Junction& jn = junction_;
    if (next)
        classify(p, *next, jn);
    else
        jn.set(0, false, 0);
    if (next) next->start_at_rest = jn.blend == Blend::None && jn.cap_mm_s == 0;
    bool rough = p.rough_start || jn.rough;
    // A Bezier corner, or an offset corner's first piece (its shift, or the turn of a one-sided
    // one moved only after it), starts where the move is cut (evaluated there).
    const AxisArray* blend_start = nullptr;
    if (jn.blend == Blend::Curve) blend_start = &jn.curve.origin;
    if (jn.blend == Blend::Offset)
        blend_start = jn.has_shift_out ? &jn.shift_out.origin : &jn.curve.origin;
    // Only a line blended at both ends can vanish, and its junctions are smooth.
    const double e_length_mm = add_item_made(
        [&] { return trimmed(p.geom, p.trim_start_mm, jn.blend_l_mm, blend_start); },
        p.feed_mm_s, jn.cap_mm_s, rough, p, p.rapid);
    if (!next) return;
    double f1 = p.feed_mm_s, f2 = next->feed_mm_s;
    double feed = f1 > 0 && f2 > 0 ? std::min(f1, f2) : std::max(f1, f2);
    const bool rapid = p.rapid && next->rapid;  // blends between two rapids are rapid too
    // A blend between moves that keep at least its own length on either side is passed at one
    // speed: the moves do the speeding up and slowing down, faster than a blend can, so without
    // a jerk limit nearly all its acceleration goes to turning. In a chain of short moves the
    // blends must change speed themselves and keep the default share.
    double l = jn.blend_l_mm;
    bool isolated = !jerk_mode_ && l > 0 && e_length_mm >= l && next->geom.length_mm / 2 >= 2 * l;
    double turning = isolated ? kIsolatedBlendCentripetal : 0;
    switch (jn.blend) {
        case Blend::Offset: {
            // The shift runs along the first move at its feed. Off a line it keeps that line
            // and move (a single block stop comes at its end, within the tolerance); off an arc
            // it belongs to the next move, as the turn does, like every blend (synchronised
            // outputs switch where it starts): the move is left where the tool leaves its path.
            // A one-sided corner (one shift) made its shift's bounds and limits already.
            const Piece& shift_owner = p.geom.kind == ElementKind::Line ? p : *next;
            const bool one_sided = jn.has_shift_out != jn.has_shift_back;
            if (jn.has_shift_out && one_sided)
                add_item_with_limits(jn.shift_out, jn.shift_bounds, jn.shift_lim, shift_owner,
                                     p.rapid);
            else if (jn.has_shift_out)
                add_item(jn.shift_out, p.feed_mm_s, kInf, false, shift_owner, p.rapid,
                         kShiftCentripetal, jn.moving_axes());
            add_item(jn.curve, feed, kInf, false, *next, rapid, kIsolatedBlendCentripetal,
                     jn.moving_axes());
            if (jn.has_shift_back && one_sided)
                add_item_with_limits(jn.shift_back, jn.shift_bounds, jn.shift_lim, *next,
                                     next->rapid);
            else if (jn.has_shift_back)
                add_item(jn.shift_back, next->feed_mm_s, kInf, false, *next, next->rapid,
                         kShiftCentripetal, jn.moving_axes());
            next->trim_start_mm = jn.cut_after_mm;
            next->rough_start = false;
            return;
        }
        case Blend::Curve:
            add_item(jn.curve, feed, jn.curve_end_cap_mm_s, jn.rough || jn.curve_end_rough, *next,
                     rapid, turning, jn.moving_axes());
            next->trim_start_mm = jn.blend_l_mm;
            next->rough_start = jn.curve_end_rough;
            return;
        case Blend::Parabola:
            add_item(make_parabola(p.geom.end, p.geom.a, next->geom.a, jn.blend_l_mm), feed, kInf,
                     false, *next, rapid, turning);
            break;
        case Blend::Quartic:
            add_item(make_blend(p.geom.end, p.geom.a, next->geom.a, jn.blend_l_mm), feed, kInf,
                     false, *next, rapid);
            break;
        case Blend::None:
            break;
    }
    next->trim_start_mm = jn.blend_l_mm;
    next->rough_start = jn.rough;
}

void Planner::add_item(const Element& e, double feed, double end_cap, bool rough,
                       const Piece& owner, bool rapid, double blend_centripetal,
                       std::span<const int> moving) {
    set_item_limits(items_.emplace_back(e, moving), feed, end_cap, rough, owner, rapid,
                    blend_centripetal);
}

void Planner::set_item_limits(Item& it, double feed, double end_cap, bool rough,
                              const Piece& owner, bool rapid, double blend_centripetal) {
    double cut = reserve_ + (rough ? cfg_.junction_share : 0);
    it.lim = element_limits(it.geom, it.bounds, cfg_.limits, feed,
                            {1 - cut, 1 - cut, blend_centripetal});
    it.end_cap_mm_s = end_cap;
    it.rough = rough;
    it.line = owner.line;
    it.move_id = owner.move_id;
    it.rapid = rapid;
}

void Planner::add_item_with_limits(const Element& e, const ElementBounds& b,
                                   const ElementLimits& lim, const Piece& owner, bool rapid) {
    Item& it = items_.emplace_back(e, b);
    it.lim = lim;
    it.end_cap_mm_s = kInf;
    it.rough = false;
    it.line = owner.line;
    it.move_id = owner.move_id;
    it.rapid = rapid;
}

bool Planner::can_join(const Group& g, const Item& it) const {
    // Only smooth junctions, and only between elements with similar limits: the group runs
    // under the smallest of them.
    auto similar = [](double a, double b, double ratio) {
        if (a == 0 || b == 0) return a == b;  // 0 = unlimited jerk
        return std::min(a, b) >= ratio * std::max(a, b);
    };
    // Compared with the group's first element, so that the group cannot drift downwards.
    const Item& ref = items_[g.first];
    // The speed cap must match (a group runs under its smallest cap); acceleration and jerk
    // may differ a little.
    return std::isinf(g.end_cap_mm_s) &&
           similar(ref.lim.vcap_mm_s, it.lim.vcap_mm_s, kJoinSpeedRatio) &&
           similar(ref.lim.tangent.acc_mm_s2, it.lim.tangent.acc_mm_s2, kJoinRatio) &&
           similar(ref.lim.tangent.jerk_mm_s3, it.lim.tangent.jerk_mm_s3, kJoinRatio);
}

void Planner::build_groups() {
    // Groups formed in an earlier round are never changed: the speed where the last emitted
    // record ended was planned against them, and only appending new groups keeps it reachable.
    // Without a jerk limit every element gets its own trapezoid, which is already time-optimal.
    std::size_t max_items =
        jerk_mode_ ? std::clamp<std::size_t>(cfg_.window / 4, 1, kMaxGroupItems) : 1;
    std::size_t first_new = groups_.size();
    for (std::size_t i = grouped_end_; i < items_.size(); ++i) {
        const Item& it = items_[i];
        if (groups_.size() > first_new) {
            Group& g = groups_.back();
            if (g.end - g.first < max_items && can_join(g, it)) {
                g.end = i + 1;
                g.length_mm += it.geom.length_mm;
                g.vcap_mm_s = std::min(g.vcap_mm_s, it.lim.vcap_mm_s);
                g.tangent.acc_mm_s2 = std::min(g.tangent.acc_mm_s2, it.lim.tangent.acc_mm_s2);
                g.tangent.jerk_mm_s3 = std::min(g.tangent.jerk_mm_s3, it.lim.tangent.jerk_mm_s3);
                g.end_cap_mm_s = it.end_cap_mm_s;
                continue;
            }
        }
        groups_.push_back(
            {i, i + 1, it.geom.length_mm, it.lim.vcap_mm_s, it.end_cap_mm_s, it.lim.tangent});
    }
    grouped_end_ = items_.size();
}

std::size_t Planner::plan_and_emit(bool all) {
    std::size_t n = items_.size() - head_;
    if (n == 0) return 0;
    build_groups();
    const Group* gs = groups_.data() + group_head_;
    std::size_t m = groups_.size() - group_head_;
    vj_.assign(m + 1, 0.0);
    // Backward pass: the highest speed at each junction from which everything after it, up to
    // a stop at the window's end, can still be followed. With a jerk limit the speed reachable
    // over a length is not monotone in the speed at the other end (a ramp that must start and
    // end at zero acceleration is slow for small speed changes), so the bound takes the best
    // end speed in [0, next bound]; the best is at one of the two ends. This keeps the bounds
    // monotone in the window's end speed, which is what makes streaming safe.
    vj_[m] = 0;
    for (std::size_t i = m - 1; i >= 1; --i) {
        double bound = std::min({gs[i - 1].vcap_mm_s, gs[i].vcap_mm_s, gs[i - 1].end_cap_mm_s});
        double back = reachable_speed_mm_s(vj_[i + 1], gs[i].length_mm, gs[i].tangent);
        if (jerk_mode_ && back < bound)
            back = std::max(back, reachable_speed_mm_s(0, gs[i].length_mm, gs[i].tangent));
        vj_[i] = std::min(bound, back);
    }
    // Forward pass: as fast as can be reached from where the last emitted record ended.
    vj_[0] = v_start_;
    for (std::size_t i = 0; i < m; ++i) vj_[i + 1] = forward_speed(gs[i], vj_[i], vj_[i + 1]);
    // Emit whole groups, keeping the last half of the window for the next round.
    std::size_t keep = all ? 0 : std::min(n, cfg_.window / 2);
    std::size_t count = 0, emitted = 0;
    while (count < m && gs[count].end - head_ <= n - keep) {
        emit_group(gs[count], vj_[count], vj_[count + 1]);
        emitted += gs[count].end - gs[count].first;
        ++count;
    }
    head_ += emitted;
    group_head_ += count;
    v_start_ = vj_[count];
    compact();
    return emitted;
}

double Planner::forward_speed(const Group& g, double v, double bound) const {
    if (v <= bound) return std::min(bound, reachable_speed_mm_s(v, g.length_mm, g.tangent));
    // Rounding may leave the slow-down to `bound` a hair longer than the group: accept that.
    double slack = g.length_mm * (1 + 1e-9);
    if (ramp_distance_mm(v, bound, g.tangent) <= slack || ramp_distance_mm(v, 0, g.tangent) > slack)
        return bound;
    // Slowing to `bound` does not fit but a larger slow-down does (jerk-limited ramps, see the
    // backward pass): the largest end speed below the bound whose ramp fits.
    double lo = 0, hi = bound;
    for (int k = 0; k < 60 && hi - lo > 1e-12 * bound; ++k) {
        double mid = (lo + hi) / 2;
        (ramp_distance_mm(v, mid, g.tangent) <= g.length_mm ? lo : hi) = mid;
    }
    return lo;
}

void Planner::compact() {
    if (head_ == items_.size()) {
        items_.clear();
        groups_.clear();
        head_ = group_head_ = grouped_end_ = 0;
    } else if (head_ >= cfg_.window) {
        items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(head_));
        groups_.erase(groups_.begin(), groups_.begin() + static_cast<std::ptrdiff_t>(group_head_));
        for (Group& g : groups_) g.first -= head_, g.end -= head_;
        grouped_end_ -= head_;
        head_ = group_head_ = 0;
    }
}

namespace {

// Time at which the profile reaches s (profiles are monotone in s): find the phase, then
// regula falsi (Illinois) on its cubic.
double time_at(const Profile1D& p, double s) {
    int i = p.count - 1;
    while (i > 0 && p.phases[i].s0_mm > s) --i;
    const ProfilePhase& ph = p.phases[i];
    auto pos = [&](double dt) {
        return ph.s0_mm + ph.v0_mm_s * dt + ph.a0_mm_s2 * dt * dt / 2 +
               ph.j_mm_s3 * dt * dt * dt / 6 - s;
    };
    double lo = 0, hi = (i + 1 < p.count ? p.phases[i + 1].t0_s : p.duration_s) - ph.t0_s;
    double flo = pos(lo), fhi = pos(hi);
    if (fhi <= 0) return ph.t0_s + hi;
    const double tol = 1e-13 * std::max(1.0, s);
    auto b = detail::illinois(pos, lo, flo, hi, fhi, 1e-15,
                              [&](double, double f) { return std::fabs(f) < tol; });
    return ph.t0_s + (b.lo + b.hi) / 2;
}

// The part of p between times ta and tb, shifted to start at time 0 and position 0, into out
// (a default Profile1D).
void clip_into(Profile1D& out, const Profile1D& p, double ta, double tb, double sa) {
    for (int i = 0; i < p.count; ++i) {
        const ProfilePhase& ph = p.phases[i];
        double end = i + 1 < p.count ? p.phases[i + 1].t0_s : p.duration_s;
        if (end <= ta || ph.t0_s >= tb) continue;
        double start = std::max(ph.t0_s, ta);
        double dt = start - ph.t0_s;
        ProfilePhase& q = out.phases[out.count++];
        q.t0_s = start - ta;
        q.s0_mm = ph.s0_mm + ph.v0_mm_s * dt + ph.a0_mm_s2 * dt * dt / 2 +
                  ph.j_mm_s3 * dt * dt * dt / 6 - sa;
        q.v0_mm_s = ph.v0_mm_s + ph.a0_mm_s2 * dt + ph.j_mm_s3 * dt * dt / 2;
        q.a0_mm_s2 = ph.a0_mm_s2 + ph.j_mm_s3 * dt;
        q.j_mm_s3 = ph.j_mm_s3;
    }
    out.duration_s = tb - ta;
}

}  // namespace

void Planner::emit_group(const Group& g, double v_in, double v_out) {
    if (g.end - g.first == 1) {
        emit(items_[g.first], [&](Profile1D& out) {
            build_profile_into(out, g.length_mm, v_in, v_out, g.vcap_mm_s, g.tangent);
        });
        return;
    }
    const Profile1D prof = build_profile(g.length_mm, v_in, v_out, g.vcap_mm_s, g.tangent);
    // One profile over the whole group, cut at the element boundaries: the acceleration runs on
    // across them instead of returning to zero at each.
    double s = 0, t = 0;
    for (std::size_t i = g.first; i < g.end; ++i) {
        const Item& it = items_[i];
        double s_end = s + it.geom.length_mm;
        double t_end = i + 1 == g.end ? prof.duration_s : time_at(prof, s_end);
        emit(it, [&](Profile1D& out) { clip_into(out, prof, t, t_end, s); });
        s = s_end;
        t = t_end;
    }
}

// emit() writes every member of the record it makes (its slot is not cleared first): a new
// member makes this fail until emit() writes it too.
static_assert(sizeof(PreparedSegment) ==
                  sizeof(Element) + sizeof(Profile1D) + kMaxPhases * 8 + 4 + 4 + 3 + 5 +
                      sizeof(Action) + 8 + 8 + 4 + 4 + kProbeAxes * sizeof(ProbeAxis),
              "emit() writes every member of PreparedSegment: add new ones there");
static_assert(sizeof(Profile1D) == kMaxPhases * sizeof(ProfilePhase) + 8 + 4 * 8,
              "emit() writes every member of Profile1D: add new ones there");

template <class MakeProfile>
void Planner::emit(const Item& it, MakeProfile&& make_profile) {
    if (out_head_ == out_.size()) {
        out_.clear();
        out_head_ = 0;
    }
    // Every member is written here (the slot's bytes are not cleared, see RecordSlot), the
    // profile's first as make_profile expects of a default one.
    PreparedSegment& rec = out_.emplace_back().rec();
    assign_element(rec.geom, it.geom);
    rec.profile.count = 0;
    rec.profile.duration_s = rec.profile.peak_v_mm_s = 0;
    rec.profile.peak_a_mm_s2 = rec.profile.peak_j_mm_s3 = 0;
    make_profile(rec.profile);  // written in place: a 320-byte copy less per record
    const Profile1D& prof = rec.profile;
    LimitShares rate_share{1 - reserve_, 1 - reserve_};
    const ElementBounds& b = it.bounds;
    for (int i = 0; i < prof.count; ++i) {
        // Peaks of a cubic phase are at its ends (|v| and |a| are monotone within a phase).
        const ProfilePhase& ph = prof.phases[i];
        double dt = (i + 1 < prof.count ? prof.phases[i + 1].t0_s : prof.duration_s) - ph.t0_s;
        double v = std::max(ph.v0_mm_s, ph.v0_mm_s + ph.a0_mm_s2 * dt + ph.j_mm_s3 * dt * dt / 2);
        double a = std::max(std::fabs(ph.a0_mm_s2), std::fabs(ph.a0_mm_s2 + ph.j_mm_s3 * dt));
        rec.profile.peak_v_mm_s = std::max(rec.profile.peak_v_mm_s, v);
        rec.profile.peak_a_mm_s2 = std::max(rec.profile.peak_a_mm_s2, a);
        rec.profile.peak_j_mm_s3 = std::max(rec.profile.peak_j_mm_s3, std::fabs(ph.j_mm_s3));
        // Next to a junction that is not smooth the step there scales with the rate: stay at 1.
        rec.phase_rate_cap[i] = it.rough ? 1.0
                                         : rate_cap(b, cfg_.limits, v, a, std::fabs(ph.j_mm_s3),
                                                    rate_share, cfg_.max_rate);
    }
    // The phases the profile does not use stay as a default record's.
    for (int i = prof.count; i < kMaxPhases; ++i) {
        rec.profile.phases[i] = ProfilePhase{};
        rec.phase_rate_cap[i] = 0;
    }
    rec.line = it.line;
    rec.seq = seq_++;
    rec.rapid = it.rapid;
    rec.program_end = false;
    rec.rough = it.rough;
    rec.action = Action{};
    rec.dout_set = rec.dout_clear = 0;
    rec.message = 0;
    rec.move_id = it.move_id;
    rec.probe = {};
}

bool Planner::pop(PreparedSegment& out) noexcept {
    const PreparedSegment* rec = pop_ref();
    if (!rec) return false;
    out = *rec;
    return true;
}

std::size_t Planner::take(std::span<PreparedSegment> out) noexcept {
    std::size_t n = std::min(out.size(), ready());
    for (std::size_t i = 0; i < n; ++i) out[i] = out_[out_head_ + i].rec();
    out_head_ += n;
    return n;
}

}  // namespace motion
