#include "motion/sampler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "motion/jerk_stop.hpp"
#include "motion/limits.hpp"

namespace motion {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Single block: braking for a block's end starts when the deceleration that lands on it reaches
// this share of the limit, leaving room for the speed the next period could still add.
constexpr double kBlockBrakeShare = 0.8;
// Without a jerk limit r'' is free; r' still ramps over this time so the rate stays smooth.
constexpr double kRateRampS = 0.005;
// With a jerk limit a rate this close above 1 counts as 1 (the plan's own rate): a backup's
// brake, followed piece by piece, may land a rounding error above where it was computed to.
constexpr double kPlannedRate = 1 + 1e-12;
// Room cache entries filled per period ahead of need: more than the records a period can
// finish at the highest rate on short segments (0.05 mm at 120 mm/s: 2.4), so the cache is warm
// by the time the override rises, and the cost stays spread over the periods.
constexpr std::size_t kWarmRecordsPerPeriod = 8;
// The jerk-limited checks take the plan over the part of each phase a stretch covers, widened
// by this much planned time either side: the planned clock the sampler follows is summed in a
// different order than the checks sum it (rounding errors of 1e-16 s).
constexpr double kWalkPadS = 1e-9;
// A slowing move takes r' to this share of the acceleration room of its period: at the room
// itself the backup's first piece, whose check pairs the rate at the piece's end with r' at
// its start, could never pass, and the period after would brake instead (a two-period chatter
// of the acceleration).
constexpr double kRampShare = 0.97;

bool is_action(const PreparedSegment& rec) noexcept {
    return rec.action.kind != ActionKind::None;
}
struct PhasePeaks {
    double v_mm_s = 0, a_mm_s2 = 0;
};

// Largest |v| and |a| of one profile phase of duration t_s (v0 + a0 t + j t^2 / 2).
PhasePeaks phase_peaks(const ProfilePhase& ph, double t_s) noexcept {
    const double v0 = ph.v0_mm_s, a0 = ph.a0_mm_s2, j = ph.j_mm_s3;
    double v = std::max(std::fabs(v0), std::fabs(v0 + a0 * t_s + j * t_s * t_s / 2));
    if (j != 0) {
        double t_turn = -a0 / j;
        if (t_turn > 0 && t_turn < t_s) v = std::max(v, std::fabs(v0 - a0 * a0 / (2 * j)));
    }
    return {v, std::max(std::fabs(a0), std::fabs(a0 + j * t_s))};
}

// What one phase asks of axis k at r = 1: peak |velocity|, |acceleration| and |jerk| through
// the element's derivative bounds, the last two never above what the plan keeps to (`keep` of
// the limits: the planner's guarantee, tighter than the bounds on arcs).
struct AxisUse {
    double vel = 0, acc = 0, jerk = 0;
};
AxisUse axis_use(const ElementBounds& b, int k, const PhasePeaks& pk, double j_abs, double keep,
                 const AxisLimits& lim) noexcept {
    const double v = pk.v_mm_s, a = pk.a_mm_s2;
    AxisUse u;
    u.vel = v * b.g1[k];
    u.acc = std::min(a * b.g1[k] + v * v * b.g2[k], keep * lim.acc_mm_s2[k]);
    u.jerk = std::min(j_abs * b.g1[k] + 3 * v * a * b.g2[k] + v * v * v * b.g3[k],
                      keep * lim.jerk_mm_s3[k]);
    return u;
}
// ---- jerk-limited checks: the plan and the rate as ranges ----------------------------------
// The jerk-limited checks bound what an axis sees over a stretch of planned time from ranges:
// the plan's v and a (and its constant j) over the part of a phase the stretch covers, and
// r, r' over a piece of a rate path (r'' constant). Interval products keep the signs: a rate
// falling (r' < 0) while the plan speeds up (a > 0) pulls the tangential acceleration
// a r^2 + v r' back through 0 instead of adding to it.
struct Span {
    double lo = 0, hi = 0;
    double abs_max() const noexcept { return std::max(std::fabs(lo), std::fabs(hi)); }
};
Span operator+(Span x, Span y) noexcept {
    return {x.lo + y.lo, x.hi + y.hi};
}
Span operator*(Span x, Span y) noexcept {
    const double p0 = x.lo * y.lo, p1 = x.lo * y.hi, p2 = x.hi * y.lo, p3 = x.hi * y.hi;
    return {std::min({p0, p1, p2, p3}), std::max({p0, p1, p2, p3})};
}
Span scaled(double c, Span x) noexcept {
    return c >= 0 ? Span{c * x.lo, c * x.hi} : Span{c * x.hi, c * x.lo};
}

// The plan over [t_lo, t_hi] of one phase (the phase's own time): v and a as ranges, j constant.
struct PlanSpan {
    Span v, a;
    double j = 0;
};
PlanSpan plan_span(const ProfilePhase& ph, double t_lo, double t_hi) noexcept {
    const double v0 = ph.v0_mm_s, a0 = ph.a0_mm_s2, j = ph.j_mm_s3;
    auto v_at = [&](double t) { return v0 + a0 * t + j * t * t / 2; };
    PlanSpan out;
    const double va = v_at(t_lo), vb = v_at(t_hi);
    out.v = {std::min(va, vb), std::max(va, vb)};
    if (j != 0) {
        const double t_turn = -a0 / j;
        if (t_turn > t_lo && t_turn < t_hi) {
            const double vt = v_at(t_turn);
            out.v = {std::min(out.v.lo, vt), std::max(out.v.hi, vt)};
        }
    }
    const double aa = a0 + j * t_lo, ab = a0 + j * t_hi;
    out.a = {std::min(aa, ab), std::max(aa, ab)};
    out.j = j;
    return out;
}

// Largest x >= 0 with sqrt((x t + c)^2 + n^2) + x l <= m (c, n, t, l >= 0): on an arc the
// tangential part (amplitude x t), a part along it (c) and one across it (n) of the in-plane
// acceleration or jerk add as a rotating vector; l is a helix's linear part. The positive root
// of (t^2 - l^2) x^2 + 2 (t c + m l) x - (m^2 - c^2 - n^2) = 0, written so that it stays exact
// for t = l and for l = 0; 0 when c and n use up m.
double rotating_room(double t, double l, double c, double n, double m) noexcept {
    const double k = m * m - c * c - n * n;
    if (!(k > 0) || c >= m) return 0;
    const double b = t * c + m * l;
    const double disc = b * b + (t * t - l * l) * k;
    if (!(disc >= 0)) return 0;
    const double den = b + std::sqrt(disc);
    return den > 0 ? k / den : kInf;
}

// Along the path, with the plan scaled in time: tangential acceleration a_t = a r^2 + v r',
// tangential jerk j_t = j r^3 + 3 a r r' + v r'', speed u = v r.
struct PathLoad {
    Span at, jt, u;
};
PathLoad path_load(const PlanSpan& pl, const RateSpan& rb) noexcept {
    const Span r{std::max(rb.r_lo, 0.0), std::max(rb.r_hi, 0.0)};
    const Span rd{rb.rd_lo, rb.rd_hi};
    const Span r2 = r * r;
    const Span r3{r2.lo * r.lo, r2.hi * r.hi};
    PathLoad out;
    out.at = pl.a * r2 + pl.v * rd;
    out.jt = scaled(pl.j, r3) + scaled(3, pl.a * r * rd) + scaled(rb.rdd, pl.v);
    out.u = pl.v * r;
    return out;
}

// Bounds on axis k's |acceleration| a_t p' + u^2 p'' and |jerk| j_t p' + 3 u a_t p'' + u^3 p'''.
// On an arc the in-plane p' and p'' are perpendicular and p''' is antiparallel to p' (rotating
// vectors of amplitudes tangential_in_plane, g2, g3; a helix's linear part only moves with p'),
// so the parts across add in quadrature; elsewhere every term adds.
struct AxisLoad {
    double acc = 0, jerk = 0;
};
AxisLoad axis_load(const ElementBounds& b, int k, const PathLoad& pl) noexcept {
    const double at = pl.at.abs_max(), jt = pl.jt.abs_max(), u = pl.u.abs_max();
    const double tip = b.tangential_in_plane[k];
    AxisLoad out;
    if (tip > 0) {
        const double lin = b.linear[k], g2 = b.g2[k], g3 = b.g3[k];
        out.acc = std::hypot(at * tip, u * u * g2) + at * lin;
        // |j_t tip - u^3 g3| is bilinear in (j_t, u^3): largest at a corner of their ranges.
        const double w_lo = pl.u.lo * pl.u.lo * pl.u.lo, w_hi = pl.u.hi * pl.u.hi * pl.u.hi;
        const double along = std::max(
            {std::fabs(pl.jt.lo * tip - w_lo * g3), std::fabs(pl.jt.lo * tip - w_hi * g3),
             std::fabs(pl.jt.hi * tip - w_lo * g3), std::fabs(pl.jt.hi * tip - w_hi * g3)});
        out.jerk = std::hypot(along, 3 * u * at * g2) + jt * lin;
    } else {
        out.acc = at * b.g1[k] + u * u * b.g2[k];
        out.jerk = jt * b.g1[k] + 3 * u * at * b.g2[k] + u * u * u * b.g3[k];
    }
    return out;
}
}  // namespace

AxisPeak ranged_axis_peak(const ElementBounds& b, int k, const ProfilePhase& ph, double t_lo,
                          double t_hi, const RateSpan& rate) noexcept {
    const AxisLoad load = axis_load(b, k, path_load(plan_span(ph, t_lo, t_hi), rate));
    return {load.acc, load.jerk};
}

PreparedSegment action_record(const AxisArray& pos_mm, const Action& action,
                              std::int32_t line) noexcept {
    PreparedSegment rec{};
    rec.geom = make_line(pos_mm, pos_mm);
    rec.profile.count = 1;         // one phase at rest, of zero duration
    rec.phase_rate_cap.fill(1e9);  // nothing moves, so no rate can exceed a limit
    rec.line = line;
    rec.program_end = true;  // stands at rest: the queue may end here
    rec.action = action;
    return rec;
}

MotionSample sample(const PreparedSegment& seg, double t) noexcept {
    PathState ps = seg.profile.at(t);
    if (t >= seg.profile.duration_s) ps.s_mm = seg.geom.length_mm;
    CurvePoint cp;
    evaluate(seg.geom, ps.s_mm, cp);
    MotionSample out;
    double v = ps.v_mm_s, a = ps.a_mm_s2, j = ps.j_mm_s3;
    for (int k = 0; k < kAxes; ++k) {
        out.pos_mm[k] = cp.p[k];
        out.vel_mm_s[k] = v * cp.d1[k];
        out.acc_mm_s2[k] = a * cp.d1[k] + v * v * cp.d2[k];
        out.jerk_mm_s3[k] = j * cp.d1[k] + 3 * v * a * cp.d2[k] + v * v * v * cp.d3[k];
    }
    out.line = seg.line;
    return out;
}

SamplerConfig sampler_config(const PlannerConfig& p) {
    SamplerConfig s;
    s.limits = p.limits;
    s.override_reserve = override_reserve_in_effect(p);
    s.max_rate = p.max_rate;
    s.junction_share = p.junction_share;
    return s;
}

RateLimits rate_limits(const SamplerConfig& cfg) noexcept {
    // Half of the reserve each for the r' and r'' terms of the jerk; all of it for the r' term
    // of the acceleration.
    double eta = cfg.override_reserve;
    double vm = kInf, am = kInf;
    for_each_limit(cfg.limits, [&](double vel, double acc, double jerk) {
        vm = std::min(vm, eta * acc / vel);
        if (jerk > 0) {
            vm = std::min(vm, eta / 2 * jerk / (3 * cfg.max_rate * acc));
            am = std::min(am, eta / 2 * jerk / vel);
        }
    });
    // Without a jerk limit r'' is free; a 5 ms ramp of r' keeps the rate smooth anyway.
    if (!std::isfinite(am)) am = vm / kRateRampS;
    return {vm, am};
}

Sampler::Sampler(const SamplerConfig& cfg, SpscRing<PreparedSegment>& ring, const AxisArray& start)
    : cfg_(cfg),
      joint_space_(joint_space_limits(cfg.limits.joints)),
      rl_(rate_limits(cfg)),
      last_limits_(rl_),
      ring_(ring),
      rooms_(std::max<std::size_t>(cfg.lookahead_records, 1)) {
    last_.pos_mm = start;
    jerk_limited_ = jerk_limited(cfg.limits);
}

// The front record's outputs fall due once: when the path first moves in it, or when it is
// left (also when it was crossed within one period).
void Sampler::enter_front() noexcept {
    if (front_entered_ || ring_.size() == 0) return;
    front_entered_ = true;
    const PreparedSegment& rec = ring_.peek(0);
    outputs_due_.message = std::max(outputs_due_.message, rec.message);
    if ((rec.dout_set | rec.dout_clear) == 0) return;
    outputs_due_.set = (outputs_due_.set & ~rec.dout_clear) | rec.dout_set;
    outputs_due_.clear = (outputs_due_.clear & ~rec.dout_set) | rec.dout_clear;
}

void Sampler::pop_front() noexcept {
    enter_front();
    drop_front();
}

Sampler::SyncOutputs Sampler::take_sync_outputs() noexcept {
    const SyncOutputs due = outputs_due_;
    outputs_due_ = {};
    return due;
}

void Sampler::set_feed_override(double scale) noexcept {
    override_ = std::clamp(std::isfinite(scale) ? scale : 0.0, 0.0, cfg_.max_rate);
}

void Sampler::set_rapid_override(double scale) noexcept {
    rapid_override_ = std::clamp(std::isfinite(scale) ? scale : 0.0, 0.0, cfg_.max_rate);
}

double Sampler::current_override() const noexcept {
    return ring_.size() > 0 && ring_.peek(0).rapid ? rapid_override_ : override_;
}

void Sampler::set_hold(bool on) noexcept {
    hold_ = on;
}

void Sampler::abort() noexcept {
    abort_ = true;
}

void Sampler::clear_abort() noexcept {
    if (!status_.aborted) return;
    abort_ = false;
    fault_ = false;
    brake_ = Brake::None;
    action_done_ = false;
    block_released_ = false;
    front_entered_ = false;
    jog_.clear();
    status_.aborted = false;
    tau_ = 0;
}

void Sampler::fault_stop() noexcept {
    abort_ = true;
    fault_ = true;
}

void Sampler::set_single_block(bool on) noexcept {
    single_block_ = on;
}

void Sampler::resume_block() noexcept {
    if (!status_.block_paused) return;
    block_released_ = true;
    status_.block_paused = false;
}

const Action* Sampler::pending_action() const noexcept {
    if (!status_.action_pending || ring_.size() == 0) return nullptr;
    return &ring_.peek(0).action;
}

void Sampler::action_done() noexcept {
    if (status_.action_pending) action_done_ = true;
}

double Sampler::rate_target(double dt) noexcept {
    if (abort_ || hold_) return 0;
    return std::min(current_override(), jerk_limited_ ? rate_cap_ahead() : rate_cap_free(dt));
}

double Sampler::rate_cap_ahead() const noexcept {
    if (std::max(override_, rapid_override_) <= 1 && r_ <= 1 && rd_ <= 0) {
        return kInf;  // every plan holds at rate <= 1
    }
    // Planned time that can pass before the rate could be brought down to 1: phases starting
    // within it must have their caps respected from now on.
    // The bounds in use lately (the room-based ones, at least the fixed ones) set the reach.
    const double vm = std::max(rl_.max_rate_per_s, last_limits_.max_rate_per_s);
    const double am = std::max(rl_.max_rate_per_s2, last_limits_.max_rate_per_s2);
    double up = std::max(rd_, 0.0);
    double over = std::max(0.0, r_ + up * up / (2 * am) - 1);
    double t_down = up / am + over / vm + vm / am;
    double horizon = tau_ + cfg_.max_rate * t_down;  // in the front record's time
    std::size_t n = std::min(ring_.size(), cfg_.lookahead_records);
    double cap = kInf, start = 0;  // start: planned time at which the record begins
    bool end_seen = false;
    for (std::size_t i = 0; i < n && start < horizon && !end_seen; ++i) {
        const PreparedSegment& s = ring_.peek(i);
        const Profile1D& p = s.profile;
        for (int ph = 0; ph < p.count; ++ph) {
            double ph_end = start + (ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s);
            if (ph_end >= tau_ && start + p.phases[ph].t0_s <= horizon)
                cap = std::min(cap, s.phase_rate_cap[ph]);
        }
        start += p.duration_s;
        end_seen = s.program_end;
    }
    if (start < horizon && !end_seen) cap = 1;  // unknown records ahead: plan rate is safe
    return cap;
}

namespace {
struct RateState {
    double r = 0, rd = 0;
};

// Follows one piece exactly (r'' constant); returns the planned time passed.
double step_rate(RateState& s, const RatePiece& pc) noexcept {
    const double h = pc.h, u = pc.u;
    const double passed = s.r * h + s.rd * h * h / 2 + u * h * h * h / 6;
    s.r += s.rd * h + u * h * h / 2;
    s.rd += u * h;
    if (pc.zero_rd) s.rd = 0;
    if (pc.r_snap >= 0) s.r = pc.r_snap;
    return passed;
}

// The time-optimal move of (r, r') towards (target, 0) with |r'| <= vm and |r''| <= am, as
// constant-r'' pieces covering dt. An r' beyond vm (the bounds shrank) is first brought back.
void rate_path(RateState s, double target, double dt, const RateLimits& lim,
               RatePath& out) noexcept {
    const double vm = lim.max_rate_per_s, am = lim.max_rate_per_s2;
    double left = dt;
    auto take = [&](const RatePiece& pc) {  // false when dt ends inside it
        const double h = std::min(left, pc.h);
        RatePiece part = pc;
        if (h < pc.h) part = {pc.u, h, false, -1};
        out.add(part);
        step_rate(s, part);
        left -= h;
        return h == pc.h;
    };
    for (int iter = 0; iter < 6 && left > 0; ++iter) {
        const double d = target - s.r;
        if (std::fabs(d) <= 1e-12 && std::fabs(s.rd) <= 1e-9) {
            take({0, 0, true, target});
            break;
        }
        if (std::fabs(s.rd) > vm) {
            const double sg = s.rd > 0 ? 1.0 : -1.0;
            if (!take({-sg * am, (std::fabs(s.rd) - vm) / am, false, -1})) break;
            s.rd = sg * vm;
            continue;
        }
        const double stop = s.rd * std::fabs(s.rd) / (2 * am);
        const double sg = d - stop > 0 ? 1.0 : (d - stop < 0 ? -1.0 : (s.rd > 0 ? -1.0 : 1.0));
        const double vp = sg * std::min(vm, std::sqrt(std::max(0.0, sg * d * am + s.rd * s.rd / 2)));
        const double ta = std::max(0.0, (vp - s.rd) / (sg * am));
        const double da = (vp * vp - s.rd * s.rd) / (2 * sg * am);
        const double dc = vp * vp / (2 * sg * am);
        const double tb = vp != 0 ? std::max(0.0, (d - da - dc) / vp) : 0.0;
        const double tc = std::fabs(vp) / am;
        if (!take({sg * am, ta, false, -1}) || !take({0, tb, false, -1}) ||
            !take({-sg * am, tc, false, -1}))
            break;
        take({0, 0, true, target});  // landed on the target: remove the rounding drift
    }
    if (left > 0) out.add({0, left, false, -1});
}

// r' towards rd_goal at |r''| = am, then held, for dt: a move that leaves the landing to its
// backup (slowing: rd_goal < 0; speeding up: rd_goal > 0).
void ramp_path(RateState s, double rd_goal, double am, double dt, RatePath& out) noexcept {
    double left = dt;
    if (s.rd != rd_goal) {
        const double h = std::min(left, std::fabs(s.rd - rd_goal) / am);
        out.add({s.rd > rd_goal ? -am : am, h, false, -1});
        left -= h;
    }
    if (left > 0) out.add({0, left, false, -1});
}

// The backup after a move: r' braked to 0 at |r''| = am, then, above 1, r brought down to 1
// (|r'| <= vm, |r''| <= am) and held. False when the brake would take r below 0.
bool brake_path(RateState s, const RateLimits& lim, RatePath& out) noexcept {
    const double vm = lim.max_rate_per_s, am = lim.max_rate_per_s2;
    if (s.rd != 0) {
        out.add({s.rd > 0 ? -am : am, std::fabs(s.rd) / am, true, -1});
        s.r += s.rd * std::fabs(s.rd) / (2 * am);
    }
    if (s.r < -1e-12) return false;
    const double over = s.r - 1;
    if (over <= 0) return true;
    const double ramp_s = vm / am;
    if (over <= vm * ramp_s) {
        const double t = std::sqrt(over / am);
        out.add({-am, t, false, -1});
        out.add({am, t, true, 1.0});
    } else {
        out.add({-am, ramp_s, false, -1});
        out.add({0, (over - vm * ramp_s) / vm, false, -1});
        out.add({am, ramp_s, true, 1.0});
    }
    return true;
}

// The first `dt` of path (split where needed) into `head`; path keeps the rest.
void split_path(RatePath& path, double dt, RatePath& head) noexcept {
    RatePath rest;
    double left = dt;
    for (int i = 0; i < path.count; ++i) {
        const RatePiece& pc = path.pieces[static_cast<std::size_t>(i)];
        if (left <= 0) {
            rest.add(pc);
        } else if (pc.h <= left) {
            head.add(pc);
            left -= pc.h;
        } else {
            head.add({pc.u, left, false, -1});
            rest.add({pc.u, pc.h - left, pc.zero_rd, pc.r_snap});
            left = 0;
        }
    }
    if (left > 0) head.add({0, left, false, -1});  // the backup has ended: r held
    path = rest;
}
}  // namespace

// With a jerk limit: one period of the rate (module comment in sampler.hpp). The proposal is
// the time-optimal move towards the target under the room ahead, tried again at a quarter of
// it; it is taken only with a backup that rate_path_safe() accepts; else the period follows
// the backup accepted before. By induction the state always has a checked backup: at rest
// with r <= 1 and r' = 0 the empty one (hold).
double Sampler::advance_rate_jerk(double target, double dt) noexcept {
    if (rd_ == 0 && r_ == target && r_ <= kPlannedRate) {  // steady at or below the plan's rate
        cert_.count = 0;
        rdd_ = 0;
        return r_ * dt;
    }
    double vm_acc = 0;
    const RateLimits room = jerk_room_limits(target, dt, &vm_acc);
    // Slowing (a hold, an abort, an override down) and speeding up towards a rate <= 1 (an
    // override up; a target above 1 is reached through 1) try the directed moves first.
    const bool slowing = target < r_ && target < 1 && r_ <= kPlannedRate;
    const bool raising = target > r_ && r_ < 1;
    if (slowing || raising) {
        double passed = 0;
        if (directed_moves(slowing ? target : std::min(target, 1.0), dt, room, vm_acc, passed))
            return passed;
    }
    for (double scale : {1.0, 0.25}) {
        const RateLimits lim{room.max_rate_per_s * scale, room.max_rate_per_s2 * scale};
        RatePath move;
        rate_path({r_, rd_}, target, dt, lim, move);
        RateState end{r_, rd_};
        for (int i = 0; i < move.count; ++i) step_rate(end, move.pieces[static_cast<std::size_t>(i)]);
        RatePath backup;
        if (!brake_path(end, lim, backup) || !certify(move, backup, lim)) continue;
        return apply_rate(move);
    }
    RatePath head;
    split_path(cert_, dt, head);
    return apply_rate(head);
}

// The directed moves of a rate change towards `goal` (module comment in sampler.hpp): while
// slowing (goal < r) r'' < 0 against the plan's jerk, while speeding up (goal > r, goal <= 1)
// r'' > 0 likewise, each with a backup from its end that brakes r' in pieces at the room of
// each stretch (coast_backup()) and still lands on the near side of the goal; else the least
// r'' that keeps the tangential jerk within the limit; else the landing along a fresh backup.
// True with the planned time passed when one of them was taken.
bool Sampler::directed_moves(double goal, double dt, const RateLimits& room, double vm_acc,
                             double& passed) noexcept {
    const bool down = goal < r_;
    // sg: the sign of the r' the move heads for; r'' of that sign speeds the change.
    const double sg = down ? -1.0 : 1.0;
    // In the order tried:
    // - ramp: r'' of sign sg with the room the plan's jerk leaves on that side
    //   (signed_jerk_room(): nearly 2 J against the plan's jerk), r' to the acceleration room
    //   of this period at the rate now (vm_acc, over the whole stretch ahead, assumes the rate
    //   may fall to 0 there, where a r^2 no longer helps a slowing move);
    // - where that side has no room (the plan's terms alone pull the tangential jerk to the
    //   limit, or nearly): the least r'' that keeps it there, often 0 (coasting);
    // each taken only while the backup from its end (coast_backup()) still lands on the near
    // side of the goal and the whole passes the check;
    // - else land now along a fresh backup (its first period).
    // So the rate changes as fast as the jerk and the acceleration allow and the landing
    // comes as late as the room allows, as in the shortest stop. The room for r'' over this
    // period falls as r' grows in it (the 3 a r r' term), nearly linearly in |r''|: the room
    // f0 at r' as it is, f1 at the cap, and the crossing |r''| = f(|r''|) of the line through
    // them, taken once more.
    const double rise = std::max(rd_, 0.0) * dt;
    const double pad = (r_ + (down ? 0.0 : rise)) * dt + kWalkPadS;
    double rd_room = 0, brake_min = 0;
    auto room_toward = [&](double am) {
        WalkFrom at;
        if (down) {
            const RateSpan box{std::max(0.0, r_ + (std::min(rd_, 0.0) - am * dt) * dt), r_,
                               rd_ - am * dt, rd_, 0};
            const SignedRoom sr = signed_jerk_room(tau_, tau_ + pad, box, at);
            rd_room = sr.rd_down;
            brake_min = sr.up_min;
            return sr.down;
        }
        const RateSpan box{std::max(0.0, r_ + std::min(rd_, 0.0) * dt), r_ + rise + am * dt * dt,
                           rd_, rd_ + am * dt, 0};
        const SignedRoom sr = signed_jerk_room(tau_, tau_ + pad + am * dt * dt * dt, box, at);
        rd_room = sr.rd_up;
        brake_min = sr.down_min;
        return sr.up;
    };
    const double f0 = room_toward(0);
    const double least_brake = brake_min;
    const double am_cap = std::min(f0, cfg_.max_rate / (kRateRampS * kRateRampS));
    double am1 = 0;
    if (am_cap > rl_.max_rate_per_s2) {
        const double f1 = room_toward(am_cap);
        const double slope = std::max(0.0, (f0 - f1) / am_cap);
        const double guess = std::min(am_cap, f0 / (1 + slope));
        am1 = am_cap;
        if (guess < am_cap) {
            // Once more along the line through (guess, f(guess)) and (am_cap, f1): the room
            // is not quite linear in |r''|, and the first crossing falls short of it.
            const double fg = room_toward(guess);
            am1 = std::min(guess, fg);
            const double s = (f1 - fg) / (am_cap - guess);
            const double better = s < 0 ? (fg - s * guess) / (1 - s) : am_cap;
            if (fg > guess && better > guess)
                am1 = std::max(am1, std::min(better, room_toward(better)));
        }
    }
    const double vm_move = std::clamp(rd_room, vm_acc, cfg_.max_rate / kRateRampS);
    auto try_move = [&](const RatePath& move, double am_hint) {
        RateState end{r_, rd_};
        double tau_end = tau_;
        for (int i = 0; i < move.count; ++i)
            tau_end += step_rate(end, move.pieces[static_cast<std::size_t>(i)]);
        RatePath backup;
        double r_end = 0;
        if (!coast_backup(end.r, end.rd, tau_end, am_hint, backup, r_end) ||
            (down ? r_end < goal - 1e-9 : r_end > goal + 1e-9))
            return false;
        // What the next periods' reach estimates (jerk_room_limits(), rate_cap_ahead())
        // take as the r' to brake and the r'' to brake it with: the r' reached, not the cap.
        return certify(move, backup,
                       {std::max(std::fabs(end.rd), rl_.max_rate_per_s),
                        std::max(am_hint, room.max_rate_per_s2)});
    };
    if (am1 > rl_.max_rate_per_s2) {
        RatePath move;
        ramp_path({r_, rd_}, sg * kRampShare * vm_move, am1, dt, move);
        if (try_move(move, am1)) {
            passed = apply_rate(move);
            return true;
        }
        if (!down && approach(goal, dt, {kRampShare * vm_move, am1}, passed)) return true;
        if (!down && rd_ > 0) {
            // Riding a room that shrinks as r grows (the acceleration's, or the backup's
            // brake against the plan's jerk): r' let down at a quarter of the ramp's |r''|
            // rather than a landing's whole brake and the ramp back the period after (which
            // turned the path's jerk from +J to -0.9 J and back every other period).
            RatePath ease;
            const double u = 0.25 * am1;
            const double h = std::min(dt, rd_ / u);
            ease.add({-u, h, h < dt, -1});
            if (h < dt) ease.add({0, dt - h, false, -1});
            if (try_move(ease, am1)) {
                passed = apply_rate(ease);
                return true;
            }
        }
    } else if (sg * rd_ > 0) {
        RatePath move;
        const double u = least_brake * (1 + 1e-6);
        const double h = u > 0 ? std::min(dt, sg * rd_ / u) : dt;
        move.add({-sg * u, h, h < dt, -1});
        if (h < dt) move.add({0, dt - h, false, -1});
        if (try_move(move, std::max(u, room.max_rate_per_s2))) {
            passed = apply_rate(move);
            return true;
        }
    }
    if (sg * rd_ <= 0) return false;
    // The same pieces after a coast that takes r as far as they would land short of the
    // goal land on it, which a hold needs to end (r = 0) and a rise to end at its target.
    RatePath landing;
    double r_end = 0;
    const double hint = std::max(am1, room.max_rate_per_s2);
    if (!coast_backup(r_, rd_, tau_, hint, landing, r_end)) return false;
    RatePath shifted;
    if (sg * (goal - r_end) > 0 && r_end <= kPlannedRate) {
        shifted.add({0, (r_end - goal) / -rd_, false, -1});
        for (int i = 0; i < landing.count; ++i)
            shifted.add(landing.pieces[static_cast<std::size_t>(i)]);
        RatePiece& last = shifted.pieces[static_cast<std::size_t>(shifted.count - 1)];
        if (last.zero_rd) last.r_snap = goal;
    }
    for (RatePath* path : {&shifted, &landing}) {
        if (path->count == 0 || path->count == RatePath::kMaxPieces || !rate_path_safe(*path))
            continue;
        RatePath head;
        split_path(*path, dt, head);
        cert_ = *path;
        last_limits_ = {std::max(sg * rd_, rl_.max_rate_per_s), hint};
        passed = apply_rate(head);
        return true;
    }
    return false;
}

// Speeding up close to the goal, where the ramp's backup would land past it: the time-optimal
// move onto the goal under `lim` (rate_path()), with the brake at lim's |r''| as its backup,
// which lands on the goal (or short of it). Without it the landing coasts at the r' it has,
// which near the goal can be small (it took 0.15 s at r' = 0.006 / s for the last 0.1 %).
bool Sampler::approach(double goal, double dt, const RateLimits& lim, double& passed) noexcept {
    RatePath move;
    rate_path({r_, rd_}, goal, dt, lim, move);
    RateState end{r_, rd_};
    for (int i = 0; i < move.count; ++i) step_rate(end, move.pieces[static_cast<std::size_t>(i)]);
    RatePath backup;
    if (!brake_path(end, lim, backup) ||
        end.r + end.rd * end.rd / (2 * lim.max_rate_per_s2) > goal + 1e-9)
        return false;
    if (!certify(move, backup, lim)) return false;
    passed = apply_rate(move);
    return true;
}

bool Sampler::certify(const RatePath& move, const RatePath& backup,
                      const RateLimits& after) noexcept {
    RatePath whole = move;
    for (int i = 0; i < backup.count; ++i) whole.add(backup.pieces[static_cast<std::size_t>(i)]);
    if (whole.count >= RatePath::kMaxPieces || !rate_path_safe(whole)) return false;
    cert_ = backup;
    last_limits_ = after;
    return true;
}

double Sampler::apply_rate(const RatePath& path) noexcept {
    RateState s{r_, rd_};
    double passed = 0, u = 0;
    for (int i = 0; i < path.count; ++i) {
        const RatePiece& pc = path.pieces[static_cast<std::size_t>(i)];
        passed += step_rate(s, pc);
        if (pc.h > 0) u = pc.u;
        if (pc.zero_rd) u = 0;
    }
    r_ = std::max(s.r, 0.0);
    rd_ = s.rd;
    rdd_ = u;
    return std::max(passed, 0.0);
}

// Calls visit(rec, bounds, limits, phase, t_lo, t_hi, duration) for every phase of the ring's
// motion records that overlaps planned time [from, to] (the front record's time), with [t_lo, t_hi]
// the part of the phase (in its own time) that the stretch covers, widened by kWalkPadS for the
// rounding of the planned clock, in order, until visit returns false (Walk::Stopped).
// Walk::Unknown: the ring (or the look-ahead) ends before `to`. `at` carries where the walk may
// start between calls with rising `from` (the records wholly before it are skipped for good). The
// records' bounds come from the cache (cached()). With a linear kinematics' joints listed in the
// limits, each phase is visited once more with the joints' bounds and limits, joint j in place
// of axis j.
template <class Visit>
Sampler::Walk Sampler::walk_phases(double from, double to, WalkFrom& at, Visit&& visit) noexcept {
    const std::size_t n = std::min(ring_.size(), cfg_.lookahead_records);
    double start = at.start_s;
    for (std::size_t i = at.index; i < n && start <= to; ++i) {
        const PreparedSegment& rec = ring_.peek(i);
        const Profile1D& p = rec.profile;
        if (start + p.duration_s < from && i == at.index) {
            at.index = i + 1;
            at.start_s = start + p.duration_s;
        } else if (start + p.duration_s >= from && !is_action(rec)) {
            const RecordCache& c = cached(i);
            for (int ph = 0; ph < p.count; ++ph) {
                const double t0 = p.phases[ph].t0_s;
                const double t1 = ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s;
                if (start + t1 < from || start + t0 > to) continue;
                const double len = std::max(0.0, t1 - t0);
                const double lo = std::clamp(from - (start + t0) - kWalkPadS, 0.0, len);
                const double hi = std::clamp(to - (start + t0) + kWalkPadS, lo, len);
                if (!visit(rec, c.bounds, cfg_.limits, p.phases[ph], lo, hi, len))
                    return Walk::Stopped;
                // A linear kinematics' joints, each like an axis (limits.hpp, joint_bounds()).
                if (cfg_.limits.joints.count > 0 &&
                    !visit(rec, c.joint_bounds, joint_space_, p.phases[ph], lo, hi, len))
                    return Walk::Stopped;
            }
        }
        start += p.duration_s;
        // The sampler comes to rest at a program end (or stands on an action) and restarts
        // from rest with the rate reset: what the rate does beyond never moves anything.
        if (rec.program_end) return Walk::Covered;
    }
    return start > to ? Walk::Covered : Walk::Unknown;
}

// Bounds for the proposal: the least room, over the stretch the move and its brake may cover,
// left by each phase (over the part of it the stretch covers) at the rates reached there:
// - r' from the acceleration: the tangential acceleration an axis allows beside the
//   centripetal part at the highest speed (on an arc the two add in quadrature), with the
//   move's r' of the sign it heads in: slowing (r' < 0) where the plan speeds up (a > 0) has
//   that room plus a r^2, not minus it. The symmetric form (A - Acc r^2) / V, which also uses
//   the planner's (1 - reserve) guarantee, is taken where it gives more;
// - r' also from half the jerk left beside j r^3 (the 3 a r r' term), r'' from the other half
//   (the v r'' term).
// Never below the fixed bounds (valid anywhere at r <= 1); only a proposal: rate_path_safe()
// decides.
RateLimits Sampler::jerk_room_limits(double target, double dt, double* vm_acc_out) noexcept {
    const double vm0 = last_limits_.max_rate_per_s, am0 = last_limits_.max_rate_per_s2;
    // The highest rate the move and its brake may reach: r' at most vm0 more for that long.
    double reach_s = dt + vm0 / am0;
    const double up = std::max(rd_, 0.0);
    const double r_hi =
        std::min(cfg_.max_rate,
                 std::max({r_, r_ + up * up / (2 * am0), std::min(target, r_ + vm0 * reach_s)}));
    if (r_hi > 1) reach_s += (r_hi - 1) / vm0 + vm0 / am0;
    const bool slowing = target < r_ && target < 1;
    const double down = std::min(rd_, 0.0);
    const double r_lo = slowing ? 0.0 : std::max(0.0, r_ - down * down / (2 * am0));
    const Span r_span{r_lo, r_hi};
    const Span r2_span = r_span * r_span;
    const double js = cfg_.junction_share;
    double vm = kInf, am = kInf, vm_acc_all = kInf;
    auto visit = [&](const PreparedSegment& rec, const ElementBounds& b, const AxisLimits& lim,
                     const ProfilePhase& ph, double t_lo, double t_hi, double dur) {
        const double keep = 1 - cfg_.override_reserve - (rec.rough ? js : 0);
        const double free_a = 1 - (rec.rough ? js * r_hi : 0);
        const double free_j = 1 - (rec.rough ? js * r_hi * r_hi : 0);
        // Speeding up keeps the whole phase's peaks and the symmetric form: under the room of
        // the part ahead the rate climbs close to 1 while the plan still accelerates, and its
        // r' then has to be braked in the jerk phase that ends the acceleration, where little
        // room is left (measured: 40 % -> 100 % in the first acceleration took up to 0.54 s
        // that way, 0.15 s with the whole phase).
        const PlanSpan pl = slowing ? plan_span(ph, t_lo, t_hi) : plan_span(ph, 0, dur);
        const PhasePeaks pk{pl.v.abs_max(), pl.a.abs_max()};
        const Span plan_at = pl.a * r2_span;  // a r^2 over the rates the move may pass
        const double u_hi = pk.v_mm_s * r_hi;
        for (int q = 0; q < b.axis_count; ++q) {
            const int k = b.axes[q];
            const AxisUse use = axis_use(b, k, pk, std::fabs(ph.j_mm_s3), keep, lim);
            if (use.vel <= 1e-12) continue;  // the axis does not move here
            const double tip = b.tangential_in_plane[k];
            const double m = free_a * lim.acc_mm_s2[k], cen = u_hi * u_hi * b.g2[k];
            const double at_room =
                tip > 0 ? rotating_room(tip, b.linear[k], 0, cen, m) : (m - cen) / b.g1[k];
            const bool plan_fits = plan_at.abs_max() <= at_room;
            const double signed_room =
                slowing && plan_fits ? (at_room + plan_at.lo) / pk.v_mm_s : 0.0;
            const double symmetric = (m - use.acc * r_hi * r_hi) / use.vel;
            const double vm_acc = std::max(signed_room, symmetric);
            vm = std::min(vm, vm_acc);
            vm_acc_all = std::min(vm_acc_all, vm_acc);
            if (lim.jerk_mm_s3[k] <= 0) continue;
            const double mj = free_j * lim.jerk_mm_s3[k];
            const double left = mj - use.jerk * r_hi * r_hi * r_hi;
            double vm_j = use.acc * r_hi > 1e-12 ? left / (2 * 3 * r_hi * use.acc) : kInf;
            double am_j = left / (2 * use.vel);
            if (slowing && tip > 0) {
                // On an arc the r' terms of the jerk (3 u a_t p'', a_t = a r^2 + v r') lie
                // across p' and add in quadrature to the r'' term (v r'' p') and the rest
                // along it: half of what is left along p' for r'', what that leaves across
                // for r'.
                const double a_hi = pk.a_mm_s2, j_r3 = std::fabs(ph.j_mm_s3) * r_hi * r_hi * r_hi;
                const double along0 = j_r3 * tip + u_hi * u_hi * u_hi * b.g3[k];
                if (along0 < mj) {
                    const double share = (mj - along0) / (a_hi > 0 ? 4 : 2);
                    const double along = mj - share * (a_hi > 0 ? 2 : 1);
                    const double across = std::sqrt(mj * mj - along * along);
                    double vm_q = (across / (3 * u_hi * b.g2[k]) - a_hi * r_hi * r_hi) / pk.v_mm_s;
                    if (a_hi > 0) vm_q = std::min(vm_q, share / (3 * a_hi * r_hi * tip));
                    const double am_q = share / (pk.v_mm_s * tip);
                    if (vm_q > 0 && am_q > 0 &&
                        1 / std::min(vm_q, vm_acc) + std::min(vm_q, vm_acc) / am_q <
                            1 / std::min(vm_j, vm_acc) + std::min(vm_j, vm_acc) / am_j) {
                        vm_j = vm_q;
                        am_j = am_q;
                    }
                }
            }
            vm = std::min(vm, vm_j);
            am = std::min(am, am_j);
        }
        return true;
    };
    WalkFrom at;
    if (walk_phases(tau_, tau_ + r_hi * reach_s, at, visit) == Walk::Unknown) {
        const RateLimits beyond = unknown_room(r_hi);  // only the planner's guarantees
        vm = std::min(vm, beyond.max_rate_per_s);
        am = std::min(am, beyond.max_rate_per_s2);
        vm_acc_all = std::min(vm_acc_all, beyond.max_rate_per_s);
    }
    if (vm_acc_out)
        *vm_acc_out = std::clamp(vm_acc_all, rl_.max_rate_per_s, cfg_.max_rate / kRateRampS);
    // Where nothing moves any rate change fits; the ramps stay finite (kRateRampS) anyway.
    vm = std::clamp(vm, rl_.max_rate_per_s, cfg_.max_rate / kRateRampS);
    am = std::clamp(am, rl_.max_rate_per_s2, std::max(vm / kRateRampS, rl_.max_rate_per_s2));
    return {vm, am};
}

// Whether following `path` from (tau_, r_, r_'), then holding the rate it ends at, keeps every
// axis within its limits. Each piece covers planned time [tau, tau + dtau] with r between its
// least and largest value over it (r is quadratic and r' linear in time on a piece) and r'
// between its ends. A piece at a steady r <= 1 is a pure time scale of the plan: always fine.
// The path must end with r' = 0 and r <= 1.
bool Sampler::rate_path_safe(const RatePath& path) noexcept {
    RateState s{r_, rd_};
    double tau = tau_;
    WalkFrom at;
    for (int i = 0; i < path.count; ++i) {
        const RatePiece& pc = path.pieces[static_cast<std::size_t>(i)];
        const double r1 = s.r + s.rd * pc.h + pc.u * pc.h * pc.h / 2;
        const double rd1 = s.rd + pc.u * pc.h;
        double r_hi = std::max(s.r, r1), r_lo = std::min(s.r, r1);
        if (pc.u != 0 && (s.rd > 0) != (rd1 > 0)) {  // r turns inside the piece
            const double r_turn = s.r - s.rd * s.rd / (2 * pc.u);
            r_hi = std::max(r_hi, r_turn);
            r_lo = std::min(r_lo, r_turn);
        }
        if (r_lo < -1e-9) return false;
        const RateSpan box{r_lo, r_hi, std::min(s.rd, rd1), std::max(s.rd, rd1), pc.u};
        RateState e = s;
        const double dtau = step_rate(e, pc);
        const bool pure_scale =
            box.rd_lo == 0 && box.rd_hi == 0 && pc.u == 0 && r_hi <= kPlannedRate;
        if (!pure_scale && !stretch_safe(tau, tau + dtau, box, at)) return false;
        s = e;
        tau += dtau;
    }
    return s.rd == 0 && s.r <= kPlannedRate;
}

// Per axis the tangential jerk j_t = j r^3 + 3 a r r' + v r'' may range over [lo, hi] (on a
// line +-(J - 3 u |a_t| g2 - u^3 g3) / g1, the terms added; on a planar arc the across term in
// quadrature). With the plan's terms j r^3 + 3 a r r' as a signed range [p_lo, p_hi], r'' > 0
// has (hi - p_hi) / v and r'' < 0 has (p_lo - lo) / v: against the plan's jerk nearly 2 J,
// with it what is left.
Sampler::SignedRoom Sampler::signed_jerk_room(double from, double to, const RateSpan& box,
                                              WalkFrom& at) noexcept {
    const double js = cfg_.junction_share;
    const double r_hi = std::max(box.r_hi, 0.0);
    RateSpan no_rdd = box;
    no_rdd.rdd = 0;
    double up = kInf, down = kInf, up_min = 0, down_min = 0, rd_down = kInf, rd_up = kInf;
    const Span r_span{std::max(box.r_lo, 0.0), r_hi};
    const Span r2_span = r_span * r_span;
    auto visit = [&](const PreparedSegment& rec, const ElementBounds& b, const AxisLimits& lim,
                     const ProfilePhase& ph, double t_lo, double t_hi, double) {
        const PlanSpan pl = plan_span(ph, t_lo, t_hi);
        const double v_hi = pl.v.abs_max(), v_lo = std::max(pl.v.lo, 0.0);
        if (v_hi <= 1e-12) return true;  // nothing moves: any r'' fits
        const double free_j = 1 - (rec.rough ? js * r_hi * r_hi : 0);
        const double free_a = 1 - (rec.rough ? js * r_hi : 0);
        const PathLoad load = path_load(pl, no_rdd);
        const double u = load.u.abs_max(), a_t = load.at.abs_max();
        const Span plan_at = pl.a * r2_span;
        const double u_lo = std::max(load.u.lo, 0.0);
        for (int q = 0; q < b.axis_count; ++q) {
            const int k = b.axes[q];
            if (b.g1[k] <= 1e-12) continue;
            const double ma = free_a * lim.acc_mm_s2[k], mj = free_j * lim.jerk_mm_s3[k];
            const double tip = b.tangential_in_plane[k];
            const bool planar_arc = tip > 0 && b.linear[k] == 0;
            // The tangential acceleration a r^2 + v r' the axis allows beside u^2 p'', and the
            // range [lo, hi] of the tangential jerk beside 3 u a_t p'' and u^3 p''': on a planar
            // arc p' and p'' are perpendicular and p''' antiparallel to p' (ranged_axis_peak()),
            // elsewhere the terms add.
            double m_a = 0, lo = 0, hi = 0;
            if (planar_arc) {
                const double across = u * u * b.g2[k];
                m_a = ma > across ? std::sqrt(ma * ma - across * across) / tip : -1.0;
                const double y = 3 * u * a_t * b.g2[k];
                const double room = mj > y ? std::sqrt(mj * mj - y * y) : -kInf;
                lo = (u * u * u * b.g3[k] - room) / tip;
                hi = (u_lo * u_lo * u_lo * b.g3[k] + room) / tip;
            } else {
                m_a = (ma - u * u * b.g2[k]) / b.g1[k];
                hi = (mj - 3 * u * a_t * b.g2[k] - u * u * u * b.g3[k]) / b.g1[k];
                lo = -hi;
            }
            rd_down = std::min(rd_down, (m_a + plan_at.lo) / v_hi);  // r' < 0: a_t >= -m_a
            rd_up = std::min(rd_up, (m_a - plan_at.hi) / v_hi);      // r' > 0: a_t <= m_a
            if (lim.jerk_mm_s3[k] <= 0) continue;
            up = std::min(up, (hi - load.jt.hi) / v_hi);
            down = std::min(down, (load.jt.lo - lo) / v_hi);
            // Where the plan's terms alone pass one side, r'' must pull them back by at least
            // the excess, at the lowest speed.
            if (load.jt.lo < lo)
                up_min = std::max(up_min, v_lo > 0 ? (lo - load.jt.lo) / v_lo : kInf);
            if (load.jt.hi > hi)
                down_min = std::max(down_min, v_lo > 0 ? (load.jt.hi - hi) / v_lo : kInf);
        }
        return true;
    };
    if (walk_phases(from, to, at, visit) == Walk::Unknown) {
        const RateLimits beyond = unknown_room(r_hi);
        up = std::min(up, beyond.max_rate_per_s2);
        down = std::min(down, beyond.max_rate_per_s2);
        rd_down = std::min(rd_down, beyond.max_rate_per_s);
        rd_up = std::min(rd_up, beyond.max_rate_per_s);
    }
    return {up, down, up_min, down_min, rd_down, rd_up};
}

// The first piece takes a quarter of r' (its check pairs r at its end with r' at its start, so
// a short one passes next to the acceleration limit), the next ones half, the last the rest,
// each at the room of the stretch it covers, guessed from the previous piece's |r''| (am_hint
// for the first) and taken again over the range that gives, and cut shorter where the stretch
// needs more than it allows; with no room to brake while the rate falls, a piece coasts until
// r has fallen by a tenth (the plan's j r^3 shrinks with it).
bool Sampler::coast_backup(double r, double rd, double tau, double am_hint, RatePath& out,
                           double& r_end) noexcept {
    constexpr int kMaxBrakePieces = 12;
    const double floor = rl_.max_rate_per_s2;
    const double cap = cfg_.max_rate / (kRateRampS * kRateRampS);
    double am = std::clamp(am_hint, floor, cap);
    WalkFrom at;
    int n = 0;
    while (rd != 0) {
        if (n++ >= kMaxBrakePieces) return false;
        const double mag = std::fabs(rd);
        // The |r''| range of the piece that removes `frac` of r' at |r''| = guess, over the
        // stretch and the rates it covers (the larger the guess, the shorter the piece).
        auto room_at = [&](double guess, double frac, double& h) {
            h = frac * mag / guess;
            const double rd_to = rd * (1 - frac);
            const RateSpan box{std::max(0.0, r - std::max(-rd, 0.0) * h),
                               r + std::max(rd, 0.0) * h, std::min(rd, rd_to),
                               std::max(rd, rd_to), 0};
            // `at` only moves past records wholly before tau, which never falls.
            const SignedRoom room = signed_jerk_room(tau, tau + box.r_hi * h + kWalkPadS, box, at);
            // A hair inside: at the edge itself the check's sums round either way.
            return rd < 0 ? Span{room.up_min * (1 + 1e-6), std::min(room.up * (1 - 1e-6), cap)}
                          : Span{room.down_min * (1 + 1e-6), std::min(room.down * (1 - 1e-6), cap)};
        };
        // A room reaching the guess covers the piece it was taken over (a larger |r''| only
        // shortens it); a smaller one is the next guess; a stretch that needs more than it
        // allows (the plan's jerk turns round inside it) is cut shorter.
        double frac = mag <= am * 2e-3 || n >= kMaxBrakePieces - 1 ? 1.0 : n == 1 ? 0.25 : 0.5;
        double guess = am, h = 0, pick = -1;
        Span got{};
        for (int it = 0; it < 6 && pick < 0; ++it) {
            got = room_at(guess, frac, h);
            if (got.hi < floor) break;
            if (got.lo > got.hi) {  // a shorter piece: less of r', at least twice as fast
                frac /= 2;
                guess = std::max(2 * guess, got.hi);
            } else if (got.hi >= guess) {
                pick = got.hi;
            } else {
                // Braking a rising r' the room shrinks as the piece grows (the rate climbs
                // into the plan's j r^3): a longer step, so it settles within the tries.
                guess = std::max(got.lo, it < 2 ? got.hi : (rd > 0 ? 0.8 : 0.9) * got.hi);
            }
        }
        if (pick < 0) {
            // No room to brake r' found (or too little to finish within the pieces): coast
            // while the rate falls by a tenth, which makes room (j r^3 shrinks).
            if (got.lo > 0 || rd > 0 || r <= 0) return false;
            const RatePiece pc{0, 0.1 * r / mag, false, -1};
            RateState s{r, rd};
            tau += step_rate(s, pc);
            r = s.r;
            out.add(pc);
            if (out.count >= RatePath::kMaxPieces - 3) return false;
            continue;
        }
        am = pick;
        const bool land = frac == 1.0;
        const RatePiece pc{rd < 0 ? am : -am, frac * mag / am, land, -1};
        RateState s{r, rd};
        tau += step_rate(s, pc);
        r = s.r;
        rd = land ? 0.0 : s.rd;
        out.add(pc);
        if (out.count >= RatePath::kMaxPieces - 3) return false;
    }
    r_end = r;
    if (r < -1e-12) return false;
    const double over = r - 1;
    if (over <= 0) return true;
    // Above 1: down to 1 at the fixed bounds (valid at any rate the caps allow).
    RatePath down;
    if (!brake_path({r, 0}, rl_, down)) return false;
    for (int i = 0; i < down.count; ++i) out.add(down.pieces[static_cast<std::size_t>(i)]);
    return out.count < RatePath::kMaxPieces;
}

// Axis k sees at most the smaller of two bounds, both over the part of each phase the stretch
// covers:
// - acceleration Acc r^2 + V |r'|, jerk Jrk r^3 + 3 Acc r |r'| + V |r''| (axis_use(): the
//   plan's peaks, Acc and Jrk at most what the planner keeps to);
// - axis_load(): the tangential acceleration and jerk as signed ranges, with an arc's
//   rotating parts in quadrature.
// Next to a rough junction the step there (junction share, times r for a velocity step, r^2
// for a curvature step) is kept out too.
bool Sampler::stretch_safe(double from, double to, const RateSpan& box, WalkFrom& at) noexcept {
    const double js = cfg_.junction_share;
    const double r_hi = box.r_hi, rdd_max = std::fabs(box.rdd);
    const double rd_max = std::max(std::fabs(box.rd_lo), std::fabs(box.rd_hi));
    const double r2 = r_hi * r_hi, r3 = r2 * r_hi;
    auto visit = [&](const PreparedSegment& rec, const ElementBounds& b, const AxisLimits& lim,
                     const ProfilePhase& ph, double t_lo, double t_hi, double dur) {
        const double keep = 1 - cfg_.override_reserve - (rec.rough ? js : 0);
        const double free_a = 1 - (rec.rough ? js * r_hi : 0);
        const double free_j = 1 - (rec.rough ? js * r2 : 0);
        const PlanSpan pl = plan_span(ph, t_lo, t_hi);
        const PhasePeaks pk{pl.v.abs_max(), pl.a.abs_max()};
        // The ranged bound costs more: it is worked out only where the first one fails.
        PathLoad load;
        bool have_load = false;
        for (int q = 0; q < b.axis_count; ++q) {
            const int k = b.axes[q];
            const AxisUse use = axis_use(b, k, pk, std::fabs(ph.j_mm_s3), keep, lim);
            if (r_hi > kPlannedRate && use.vel * r_hi > lim.vel_mm_s[k]) return false;
            const double acc_max = free_a * lim.acc_mm_s2[k];
            const bool jerk_limited = lim.jerk_mm_s3[k] > 0;
            const double jerk_max = free_j * lim.jerk_mm_s3[k];
            const bool acc_ok = use.acc * r2 + use.vel * rd_max <= acc_max;
            const bool jerk_ok =
                !jerk_limited ||
                use.jerk * r3 + 3 * r_hi * use.acc * rd_max + use.vel * rdd_max <= jerk_max;
            if (acc_ok && jerk_ok) continue;
            if (!have_load) {
                load = path_load(pl, box);
                have_load = true;
            }
            const AxisLoad ranged = axis_load(b, k, load);
            if (!acc_ok && ranged.acc > acc_max) return false;
            if (!jerk_ok && ranged.jerk > jerk_max) return false;
        }
        return true;
    };
    switch (walk_phases(from, to, at, visit)) {
        case Walk::Covered:
            return true;
        case Walk::Stopped:
            return false;
        case Walk::Unknown:  // beyond the ring nothing is known: only the fixed bounds hold
            break;
    }
    return unknown_safe(box);
}

// Beyond the records in the ring (or the look-ahead) nothing is known of the plan but what the
// planner guarantees of every record at r = 1, per axis: speed V <= vmax, |acceleration| Acc <=
// (1 - reserve) A, |jerk| Jrk <= (1 - reserve) J, and next to a rough junction Acc, Jrk <=
// (1 - reserve - junction share) of them with the step there kept out (stretch_safe()). At a
// rate r <= 1 that leaves, whichever the record is,
//     V |r'| <= A (1 - (1 - reserve) r^2 - share r (1 - r)),
//     3 r (1 - reserve) A |r'| + V |r''| <= J (1 - (1 - reserve) r^3 - share r^2 (1 - r))
// (the rough case's larger left side and the other's, the smaller right side). At r = 1 this is
// the fixed reserve bounds (rate_limits()); as the rate falls it grows, so a stop that runs
// past what the ring holds need not crawl at 1 % of the acceleration. Both sides are worst at
// the box's highest rate (the left grows with r, the right falls as long as the reserve's keep
// exceeds the junction share), so r_hi alone decides.
bool rate_fits_any_record(const SamplerConfig& cfg, const RateLimits& fixed,
                          const RateSpan& box) noexcept {
    if (box.r_hi > kPlannedRate) return false;
    const double rd = std::max(std::fabs(box.rd_lo), std::fabs(box.rd_hi));
    const double rdd = std::fabs(box.rdd);
    if (rd <= fixed.max_rate_per_s && rdd <= fixed.max_rate_per_s2) return true;  // fixed bounds
    const double r = std::clamp(box.r_hi, 0.0, 1.0), keep = 1 - cfg.override_reserve;
    const double js = cfg.junction_share;
    const double acc_left = 1 - keep * r * r - js * r * (1 - r);
    const double jerk_left = 1 - keep * r * r * r - js * r * r * (1 - r);
    bool fits = true;
    for_each_limit(cfg.limits, [&](double v, double a, double j) {
        if (v * rd > a * acc_left) fits = false;
        if (j > 0 && 3 * r * keep * a * rd + v * rdd > j * jerk_left) fits = false;
    });
    return fits;
}

bool Sampler::unknown_safe(const RateSpan& box) const noexcept {
    return rate_fits_any_record(cfg_, rl_, box);
}

// The proposal's bounds where the stretch runs past the ring: unknown_safe()'s room at rates
// up to r_hi, half the jerk left to each of the r' and r'' terms; never below the fixed bounds.
RateLimits Sampler::unknown_room(double r_hi) const noexcept {
    const double r = std::clamp(r_hi, 0.0, 1.0), keep = 1 - cfg_.override_reserve;
    const double js = cfg_.junction_share;
    const double acc_left = 1 - keep * r * r - js * r * (1 - r);
    const double jerk_left = 1 - keep * r * r * r - js * r * r * (1 - r);
    double vm = kInf, am = kInf;
    for_each_limit(cfg_.limits, [&](double v, double a, double j) {
        if (v > 0) vm = std::min(vm, a * acc_left / v);
        if (j <= 0) return;
        if (r * a > 0) vm = std::min(vm, j * jerk_left / (2 * 3 * r * keep * a));
        if (v > 0) am = std::min(am, j * jerk_left / (2 * v));
    });
    return {std::max(vm, rl_.max_rate_per_s), std::max(am, rl_.max_rate_per_s2)};
}

// Without a jerk limit, slowing down from a rate <= 1 (hold, abort, override down): as r falls,
// a r^2 leaves more of each axis's acceleration to the r' term, and the planned axis speed
// (bounded over the time it takes to change r') bounds v r' better than vmax does. Both the
// fixed reserve limits and these stay valid, so the larger of each is used.
RateLimits Sampler::rate_limits_now(double target, double dt) const noexcept {
    if (!(target < r_ && rd_ <= 0 && r_ <= 1)) return rl_;
    const AxisLimits& lim = cfg_.limits;
    const double keep = 1 - cfg_.override_reserve;
    MotionSample now = sample(ring_.peek(0), tau_);
    double horizon = dt + last_limits_.max_rate_per_s / last_limits_.max_rate_per_s2;
    double vm = kInf;
    // vel_now: an axis's or joint's |velocity| now.
    auto row = [&](double vel_now, double acc) {
        double vk = vel_now + acc * r_ * horizon;
        if (vk <= 0) return;
        // Next to an unblended kink the plan uses keep - junction_share and the kink's velocity
        // step (junction_share of a period's acceleration) scales with r, not r^2.
        const double js = cfg_.junction_share;
        const double used = std::max(keep * r_ * r_, (keep - js) * r_ * r_ + js * r_);
        vm = std::min(vm, acc * (1 - used) / vk);
    };
    for (int k = 0; k < kAxes; ++k) row(std::fabs(now.vel_mm_s[k]), lim.acc_mm_s2[k]);
    for (int j = 0; j < lim.joints.count; ++j)
        row(std::fabs(joint_component(lim.joints, j, now.vel_mm_s)), lim.joints.acc_mm_s2[j]);
    if (!std::isfinite(vm)) return rl_;
    vm = std::max(vm, rl_.max_rate_per_s);
    return {vm, vm / kRateRampS};
}

// Largest |r'| for which a r^2 + v r' stays within every axis's limit on one profile phase
// (duration t_s) of a record with derivative bounds b, at rates up to r_hi: axis k sees at most
// a_peak g1_k + v_peak^2 g2_k and v_peak g1_k. An unblended kink steps the velocity by up to
// junction_share of a period's acceleration (the planner's budget for it), scaled by the rate:
// that share is kept out of the room. Infinite where nothing moves.
double Sampler::phase_room(const ElementBounds& b, const AxisLimits& lim, const ProfilePhase& ph,
                           double t_s, double r_hi) const noexcept {
    const double usable = 1 - cfg_.junction_share * r_hi;
    const PhasePeaks pk = phase_peaks(ph, t_s);
    double best = kInf;
    for (int k = 0; k < kAxes; ++k) {
        const double vel = pk.v_mm_s * b.g1[k];
        if (vel <= 1e-12) continue;
        const double acc = pk.a_mm_s2 * b.g1[k] + pk.v_mm_s * pk.v_mm_s * b.g2[k];
        const double room = usable * lim.acc_mm_s2[k] - acc * r_hi * r_hi;
        if (room <= 0) return 0;
        best = std::min(best, room / vel);
    }
    return best;
}

// The least phase_room() over the planned time [from, to]; 0 when the ring ends before `to`
// (nothing is known beyond it).
double Sampler::room_rate(double from, double to, double r_hi) const noexcept {
    const std::size_t n = std::min(ring_.size(), cfg_.lookahead_records);
    double best = kInf, start = 0;  // start: planned time at which record i begins
    for (std::size_t i = 0; i < n; ++i) {
        const PreparedSegment& rec = ring_.peek(i);
        const Profile1D& p = rec.profile;
        if (start + p.duration_s >= from && !is_action(rec)) {
            const ElementBounds b = bounds(rec.geom);
            const JointLimits& jl = cfg_.limits.joints;
            const ElementBounds jb = jl.count > 0 ? joint_bounds(rec.geom, jl) : ElementBounds{};
            for (int ph = 0; ph < p.count; ++ph) {
                const double t0 = p.phases[ph].t0_s;
                const double t1 = ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s;
                if (start + t1 < from || start + t0 > to) continue;
                best = std::min(best, phase_room(b, cfg_.limits, p.phases[ph], t1 - t0, r_hi));
                if (jl.count > 0)
                    best =
                        std::min(best, phase_room(jb, joint_space_, p.phases[ph], t1 - t0, r_hi));
                if (best == 0) return 0;
            }
        }
        start += p.duration_s;
        if (start > to || rec.program_end) return best;
    }
    return 0;
}

// Without a jerk limit, the highest rate allowed now: for every phase P ahead with rate cap c_P
// (the planner's phase_rate_cap) starting `lead` of wall time away at the highest rate, the rate
// must be able to come down to c_P before P; on the way it can fall at least as fast as the
// least room of the phases before P (at the highest rate) or the fixed bound, so
// r <= c_P + down (lead - 2 dt). The rate never overshoots this target, and the target at the
// next period is at most down dt lower, which that period's room can follow. The end of what
// the ring holds counts as a phase with cap 1 (records beyond it are unknown).
double Sampler::rate_cap_free(double dt) noexcept {
    if (std::max(override_, rapid_override_) <= 1 && r_ <= 1) return kInf;
    const double r_max = cfg_.max_rate;
    const double reach = r_max * ((r_max - 1) / rl_.max_rate_per_s + 2 * dt);
    double allow = kInf, room = kInf, start = 0;
    auto limit_at = [&](double cap, double at) {
        const double lead = (at - tau_) / r_max - 2 * dt;
        const double down = std::max(room, rl_.max_rate_per_s);
        allow = std::min(allow, lead <= 0 ? cap : cap + down * lead);
    };
    const std::size_t n = std::min(ring_.size(), cfg_.lookahead_records);
    for (std::size_t i = 0; i < n; ++i) {
        const PreparedSegment& rec = ring_.peek(i);
        const Profile1D& p = rec.profile;
        if (start + p.duration_s >= tau_ && !is_action(rec)) {
            const RecordCache& rooms = cached(i);
            for (int ph = 0; ph < p.count; ++ph) {
                const double t0 = start + p.phases[ph].t0_s;
                const double t1 = start + (ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s);
                if (t1 < tau_) continue;
                if (t0 - tau_ > reach) return allow;
                limit_at(rec.phase_rate_cap[ph], std::max(t0, tau_));
                room = std::min(room, rooms.room_per_s[ph]);
            }
        }
        start += p.duration_s;
        if (rec.program_end) return allow;  // at rest at its end: nothing to scale beyond
    }
    limit_at(1.0, start);
    return allow;
}

// The cache entry of ring record i (i < lookahead_records), filling the entries up to it first.
// The phase durations are the record's own (t1 - t0 within the record), so the values do not
// depend on where the record sits in the queue.
const Sampler::RecordCache& Sampler::cached(std::size_t i) noexcept {
    const std::size_t size = rooms_.size();
    if (i < rooms_valid_ && rooms_[(rooms_head_ + i) % size].rec != &ring_.peek(i))
        rooms_valid_ = i;  // the ring was popped behind our back: refill from here
    for (; rooms_valid_ <= i; ++rooms_valid_) {
        const std::size_t j = rooms_valid_;
        RecordCache& e = rooms_[(rooms_head_ + j) % size];
        const PreparedSegment& rec = ring_.peek(j);
        e.rec = &rec;
        e.room_per_s.fill(kInf);
        if (is_action(rec)) continue;  // stood on, never scaled
        const Profile1D& p = rec.profile;
        e.bounds = bounds(rec.geom);
        const ElementBounds& b = e.bounds;
        const JointLimits& jl = cfg_.limits.joints;
        if (jl.count > 0) e.joint_bounds = joint_bounds(rec.geom, jl);
        for (int ph = 0; ph < p.count && !jerk_limited_; ++ph) {
            const double t0 = p.phases[ph].t0_s;
            const double t1 = ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s;
            e.room_per_s[ph] = phase_room(b, cfg_.limits, p.phases[ph], t1 - t0, cfg_.max_rate);
            if (jl.count > 0)
                e.room_per_s[ph] = std::min(
                    e.room_per_s[ph],
                    phase_room(e.joint_bounds, joint_space_, p.phases[ph], t1 - t0, cfg_.max_rate));
        }
    }
    return rooms_[(rooms_head_ + i) % size];
}

// Fills up to `count` more entries, so that raising the override above 100 % does not find
// the whole look-ahead to compute in one period.
void Sampler::warm_rooms(std::size_t count) noexcept {
    const std::size_t n = std::min(ring_.size(), rooms_.size());
    const std::size_t upto = std::min(n, rooms_valid_ + count);
    if (upto > 0 && upto > rooms_valid_) cached(upto - 1);
}

void Sampler::drop_front() noexcept {
    ring_.pop();
    rooms_head_ = (rooms_head_ + 1) % rooms_.size();
    if (rooms_valid_ > 0) --rooms_valid_;
    front_entered_ = false;
}

// Without a jerk limit r' may change from one period to the next (integrate_rate_free), so this
// period's r' only has to fit the room of the stretch it covers. The fixed and the slowing-down
// bounds (base) stay valid whatever the plan does; the larger bound is used.
RateLimits Sampler::room_limits(const RateLimits& base, double target, double dt) const noexcept {
    const double to = tau_ + 1e-12;
    double vm = room_rate(tau_, to + r_ * dt, r_);  // slowing down or steady: rate stays <= r_
    if (target > r_) {                              // speeding up: it ends at most this high
        double r_hi = r_ + std::max(vm, base.max_rate_per_s) * dt;
        vm = std::min(vm, room_rate(tau_, to + r_hi * dt, r_hi));
    }
    if (!(vm > base.max_rate_per_s)) return base;
    return {vm, std::max(vm / kRateRampS, base.max_rate_per_s2)};
}

// Without a jerk limit: r' = +-max_rate_per_s until the rate lands exactly on the target, then 0
// (no r' ramp, so no overshoot when the bound changes between periods); returns the planned time
// passed.
double Sampler::integrate_rate_free(double target, double dt, double max_rate_per_s) noexcept {
    const double d = target - r_;
    const double t_hit = max_rate_per_s > 0 ? std::fabs(d) / max_rate_per_s : kInf;
    const double slope = d > 0 ? max_rate_per_s : -max_rate_per_s;
    double passed;
    if (d == 0) {
        passed = r_ * dt;
        rd_ = 0;
    } else if (t_hit >= dt) {
        passed = r_ * dt + slope * dt * dt / 2;
        r_ += slope * dt;
        rd_ = slope;
    } else {
        passed = r_ * t_hit + slope * t_hit * t_hit / 2 + target * (dt - t_hit);
        r_ = target;
        rd_ = 0;
    }
    rdd_ = 0;
    if (r_ < 0) r_ = 0;
    return std::max(passed, 0.0);
}

// At rest at the end of `cur` (the front record, finished), with a new block next.
bool Sampler::pauses_at_block_end(const PreparedSegment& cur) const noexcept {
    if (!single_block_ || block_released_ || ring_.size() < 2) return false;
    if (ring_.peek(1).line == cur.line && !is_action(ring_.peek(1))) return false;
    return r_ == 0 || cur.profile.at(cur.profile.duration_s).v_mm_s == 0;
}

void Sampler::consume_finished_records() noexcept {
    while (ring_.size() > 0) {
        const PreparedSegment& cur = ring_.peek(0);
        if (is_action(cur) && !action_done_) {  // stand here until the owner has done it
            tau_ = 0;
            return;
        }
        if (tau_ < cur.profile.duration_s) return;
        if (ring_.size() == 1 || pauses_at_block_end(cur)) {
            tau_ = cur.profile.duration_s;
            return;
        }
        if (ring_.peek(1).line != cur.line || is_action(ring_.peek(1))) block_released_ = false;
        action_done_ = false;
        // With a jerk limit the records after a program end start from rest with the rate
        // reset to a steady r <= 1 (safe at rest, and held it needs no backup): the backups
        // checked before stop at a program end (walk_phases()), so neither the time left in
        // this period nor the rate's motion may carry past it.
        const bool rest_point = jerk_limited_ && cur.program_end;
        tau_ = rest_point ? 0.0 : tau_ - cur.profile.duration_s;
        pop_front();
        if (rest_point) {
            r_ = std::min(r_, 1.0);
            rd_ = rdd_ = 0;
            cert_.count = 0;
            return;
        }
    }
}

// The tangential deceleration that keeps every axis within its acceleration limit at path
// speed u on this record (the centripetal part u^2 p'' taken off first), never below 5 % of it.
double Sampler::decel_limit(const PreparedSegment& rec, double u) const noexcept {
    const ElementBounds b = bounds(rec.geom);
    double a = kInf, floor = kInf;
    auto rows = [&](const ElementBounds& bb, const AxisLimits& lim) {
        for (int k = 0; k < kAxes; ++k) {
            if (bb.g1[k] <= 1e-12) continue;
            const double acc = lim.acc_mm_s2[k];
            a = std::min(a, (acc - u * u * bb.g2[k]) / bb.g1[k]);
            floor = std::min(floor, 0.05 * acc / bb.g1[k]);
        }
    };
    rows(b, cfg_.limits);
    if (cfg_.limits.joints.count > 0)
        rows(joint_bounds(rec.geom, cfg_.limits.joints), joint_space_);
    if (!std::isfinite(floor)) return kInf;  // nothing moves on this record
    return std::max(a, floor);
}

// Path length from s_mm in the front record to the end of the current block: the records that
// follow with the same source line, up to an action or a program end (which end at rest).
// *planned_stop tells whether the plan itself comes to rest there.
double Sampler::block_remaining(double s_mm, bool* planned_stop) const noexcept {
    const PreparedSegment* last = &ring_.peek(0);
    double d = last->geom.length_mm - s_mm;
    const std::size_t n = std::min(ring_.size(), cfg_.lookahead_records);
    for (std::size_t i = 1; i < n && !last->program_end; ++i) {
        const PreparedSegment& rec = ring_.peek(i);
        if (rec.line != last->line || is_action(rec)) break;
        d += rec.geom.length_mm;
        last = &rec;
    }
    if (planned_stop) *planned_stop = last->profile.at(last->profile.duration_s).v_mm_s == 0;
    return d;
}

void Sampler::land_at_block_end() noexcept {
    const std::int32_t line = ring_.peek(0).line;
    while (ring_.size() > 1 && !ring_.peek(0).program_end && ring_.peek(1).line == line &&
           !is_action(ring_.peek(1)))
        pop_front();
    brake_s_mm_ = ring_.peek(0).geom.length_mm;
}

void Sampler::start_brake(Brake kind) noexcept {
    if (brake_ != Brake::None) {  // a fault during a single-block stop keeps its state
        brake_ = kind;
        return;
    }
    if (ring_.size() == 0) return;
    const PreparedSegment& cur = ring_.peek(0);
    if (is_action(cur)) return;
    const PathState ps = cur.profile.at(tau_);
    const double u = ps.v_mm_s * r_;
    if (!(u > 0)) return;  // at rest: the rate path stops it (nothing to brake)
    brake_ = kind;
    brake_s_mm_ = tau_ >= cur.profile.duration_s ? cur.geom.length_mm : ps.s_mm;
    brake_u_mm_s_ = u;
    brake_a_mm_s2_ = path_accel(ps);
}

// The path acceleration now: the planned one time-scaled by the rate (d/dt of v r).
double Sampler::path_accel(const PathState& ps) const noexcept {
    return ps.a_mm_s2 * r_ * r_ + ps.v_mm_s * rd_;
}

// The tangential jerk that keeps every axis within its jerk limit on this record (the terms of
// the curvature left out); infinite when no axis has a jerk limit.
double Sampler::path_jerk_limit(const PreparedSegment& rec) const noexcept {
    const ElementBounds b = bounds(rec.geom);
    double j = kInf;
    auto rows = [&](const ElementBounds& bb, const AxisLimits& lim) {
        for (int k = 0; k < kAxes; ++k)
            if (bb.g1[k] > 1e-12 && lim.jerk_mm_s3[k] > 0)
                j = std::min(j, lim.jerk_mm_s3[k] / bb.g1[k]);
    };
    rows(b, cfg_.limits);
    if (cfg_.limits.joints.count > 0)
        rows(joint_bounds(rec.geom, cfg_.limits.joints), joint_space_);
    return j;
}

// Single block: brake when the rest of the block is just long enough to stop in.
void Sampler::check_block_end_brake() noexcept {
    if (!single_block_ || brake_ != Brake::None || ring_.size() == 0) return;
    const PreparedSegment& cur = ring_.peek(0);
    if (is_action(cur)) return;
    const PathState ps = cur.profile.at(tau_);
    const double u = ps.v_mm_s * r_;
    if (!(u > 0)) return;
    const double s = tau_ >= cur.profile.duration_s ? cur.geom.length_mm : ps.s_mm;
    bool planned_stop = false;
    const double d = block_remaining(s, &planned_stop);
    if (planned_stop) return;  // the plan ends the block at rest itself, within the jerk limit
    const double decel = kBlockBrakeShare * decel_limit(cur, u);
    const double jerk = kBlockBrakeShare * path_jerk_limit(cur);
    const double need_mm = std::isfinite(jerk)
                               ? jerk_stop_distance({u, path_accel(ps)}, decel, jerk)
                               : u * u / (2 * decel);
    if (need_mm >= d) start_brake(Brake::BlockEnd);
}

// Single block's stop with a jerk limit: re-solved every period for the peak deceleration that
// lands on the block's end (jerk_stop.hpp). False when none within the limits does (the stop
// started too late, or the machine has no jerk limit): the caller brakes at a constant rate.
bool Sampler::jerk_brake(const PreparedSegment& cur, double left_mm, double dt,
                         JerkStopStep& step) const noexcept {
    const double jerk = path_jerk_limit(cur);
    if (!std::isfinite(jerk)) return false;
    const JerkStopState now{brake_u_mm_s_, brake_a_mm_s2_};
    const std::optional<double> decel =
        jerk_stop_decel_for(now, left_mm, decel_limit(cur, brake_u_mm_s_), jerk);
    if (!decel) return false;
    step = jerk_stop_step(now, *decel, jerk, dt);
    return true;
}

// One period of a braking stop, the position walked along the records. A fault brakes at the
// constant deceleration limit, jerk ignored. Single block lands on the block's end: with a jerk
// limit along a jerk-limited stop (jerk_brake), else at the constant deceleration that lands.
MotionSample Sampler::brake_step(double dt) noexcept {
    const PreparedSegment* cur = &ring_.peek(0);
    const double u = brake_u_mm_s_;
    double decel = 0, left = kInf, u1 = 0, ds = 0, a1 = 0, jerk = 0;
    bool stopped = false;
    JerkStopStep js;
    if (brake_ == Brake::BlockEnd) left = block_remaining(brake_s_mm_, nullptr);
    if (brake_ == Brake::BlockEnd && left > 0 && jerk_brake(*cur, left, dt, js)) {
        u1 = js.next.v_mm_s;
        a1 = js.next.a_mm_s2;
        ds = js.ds_mm;
        jerk = js.jerk_mm_s3;
        stopped = js.at_rest;
    } else {
        if (brake_ == Brake::BlockEnd)
            decel = left > 0 ? u * u / (2 * left) : kInf;
        else
            decel = decel_limit(*cur, u);
        const double t_stop = decel > 0 ? u / decel : kInf;
        u1 = t_stop <= dt ? 0.0 : u - decel * dt;
        ds = (u + u1) / 2 * std::min(dt, t_stop);  // exact for a constant deceleration
        a1 = -decel;
        stopped = u1 <= 0;
    }
    if (brake_ == Brake::BlockEnd && (stopped || ds >= left)) {
        land_at_block_end();
        cur = &ring_.peek(0);
        u1 = 0;
        stopped = true;
    } else {
        double s = brake_s_mm_ + ds;
        while (s > cur->geom.length_mm) {
            if (ring_.size() == 1 || cur->program_end || is_action(ring_.peek(1))) {
                s = cur->geom.length_mm;  // the queue ends here: nothing planned beyond
                u1 = 0;
                stopped = true;
                break;
            }
            s -= cur->geom.length_mm;
            pop_front();
            cur = &ring_.peek(0);
        }
        brake_s_mm_ = s;
    }
    brake_u_mm_s_ = u1;
    brake_a_mm_s2_ = stopped ? 0.0 : a1;
    if (brake_s_mm_ > 0) enter_front();
    CurvePoint cp;
    evaluate(cur->geom, brake_s_mm_, cp);
    for (int k = 0; k < kAxes; ++k) {
        last_.pos_mm[k] = cp.p[k];
        last_.vel_mm_s[k] = u1 * cp.d1[k];
        last_.acc_mm_s2[k] = stopped ? 0.0 : a1 * cp.d1[k] + u1 * u1 * cp.d2[k];
        last_.jerk_mm_s3[k] = stopped ? 0.0 : jerk * cp.d1[k];
    }
    last_.line = cur->line;
    status_.moving = !stopped;
    status_.braking = !stopped;
    status_.held = false;
    status_.rate = 0;
    status_.done = status_.starved = status_.action_pending = status_.block_paused = false;
    if (stopped) {
        r_ = rd_ = rdd_ = 0;
        cert_.count = 0;
        if (brake_ == Brake::Fault) {
            status_.aborted = true;
        } else {  // resume the planned profile from the block's end, at rate 0
            tau_ = cur->profile.duration_s;
            status_.block_paused = pauses_at_block_end(*cur);
        }
        brake_ = Brake::None;
    }
    return last_;
}

bool Sampler::front_is_probe() const noexcept {
    return ring_.size() > 0 && ring_.peek(0).action.kind == ActionKind::ConditionalMove;
}

// The front record is a conditional move: the jog moves the axes until its inputs come (or
// its travel ends), the owner takes the result and reports the action done; then the record
// stands at the jog's end point until the records planned from there arrive.
MotionSample Sampler::probe_step(double dt) noexcept {
    const PreparedSegment& cur = ring_.peek(0);
    if (!jog_.active()) jog_.start(sample(cur, 0).pos_mm, cur.probe, cfg_.limits);
    if (abort_) jog_.stop_now();
    const double scale = abort_ || hold_ ? 0.0 : cur.action.flag ? 1.0 : override_;
    const AxisArray before = jog_.vel_mm_s();
    jog_.step(dt, inputs_, scale);
    last_.pos_mm = jog_.pos_mm();
    last_.vel_mm_s = jog_.vel_mm_s();
    for (int k = 0; k < kAxes; ++k) last_.acc_mm_s2[k] = (last_.vel_mm_s[k] - before[k]) / dt;
    last_.jerk_mm_s3 = {};
    last_.line = cur.line;
    const bool finished = jog_.finished();
    const bool still =
        std::all_of(last_.vel_mm_s.begin(), last_.vel_mm_s.end(), [](double v) { return v == 0; });
    status_ = {};
    status_.moving = !still;
    status_.action_pending = !action_done_;
    // Done and nothing after it yet: at rest here like at a program end (the record is one).
    status_.done = finished && action_done_ && ring_.size() == 1;
    status_.held = hold_ && still && !finished;
    status_.aborted = abort_ && finished;
    status_.rate = r_;
    return last_;
}

MotionSample Sampler::advance(double dt) noexcept {
    if (fault_ && !status_.aborted && brake_ != Brake::Fault) start_brake(Brake::Fault);
    if (brake_ != Brake::None) return brake_step(dt);
    if (!status_.aborted && front_is_probe()) {
        const bool leave =
            jog_.active() && jog_.finished() && action_done_ && ring_.size() > 1 && !abort_;
        if (!leave) return probe_step(dt);
        pop_front();  // the records planned from the jog's end point follow
        jog_.clear();
        action_done_ = false;
        tau_ = 0;
    }
    if (status_.aborted) {  // discard until clear_abort(); their outputs never fall due
        while (ring_.size() > 0) drop_front();
        jog_.clear();
        last_.vel_mm_s = {};
        last_.acc_mm_s2 = {};
        last_.jerk_mm_s3 = {};
        return last_;
    }
    if (ring_.size() == 0) {
        r_ = abort_ || hold_ ? 0 : std::min(override_, 1.0);  // the next record starts at rest
        rd_ = rdd_ = 0;
        cert_.count = 0;
        status_ = {false, false, false, hold_, abort_, r_, false, false, false};
        if (abort_) status_.aborted = true;
        last_.vel_mm_s = {};
        last_.acc_mm_s2 = {};
        last_.jerk_mm_s3 = {};
        return last_;
    }
    if (status_.block_paused && single_block_ && !block_released_ && !abort_) {
        last_.vel_mm_s = {};  // stopped at a block's end: stay until resume_block()
        last_.acc_mm_s2 = {};
        last_.jerk_mm_s3 = {};
        status_.moving = false;
        return last_;
    }
    double target = rate_target(dt);
    const Profile1D& front = ring_.peek(0).profile;
    PathState now = front.at(tau_);
    // With a jerk limit, standing at the end of the ring's last record counts as rest too (a
    // jerk-limited profile ends with rounding errors of speed and acceleration; nothing moves
    // there).
    const bool standing = jerk_limited_ && ring_.size() == 1 && tau_ >= front.duration_s &&
                          now.v_mm_s * dt < 1e-9;
    if ((now.v_mm_s == 0 && (now.a_mm_s2 == 0 || !jerk_limited_)) || standing) {
        // At rest the rate has nothing to scale yet: take the target at once (with a jerk
        // limit at most 1, where holding it needs no backup; above, it rises from there).
        r_ = jerk_limited_ ? std::min(target, 1.0) : target;
        rd_ = rdd_ = 0;
        cert_.count = 0;
    }
    if (jerk_limited_) {
        tau_ += advance_rate_jerk(target, dt);
    } else {
        last_limits_ = rate_limits_now(target, dt);
        last_limits_ = room_limits(last_limits_, target, dt);
        tau_ += integrate_rate_free(target, dt, last_limits_.max_rate_per_s);
    }
    consume_finished_records();
    if (!jerk_limited_) warm_rooms(kWarmRecordsPerPeriod);
    const PreparedSegment& cur = ring_.peek(0);
    MotionSample planned = sample(cur, tau_);
    for (int k = 0; k < kAxes; ++k) {
        double v = planned.vel_mm_s[k], a = planned.acc_mm_s2[k], j = planned.jerk_mm_s3[k];
        last_.pos_mm[k] = planned.pos_mm[k];
        last_.vel_mm_s[k] = v * r_;
        last_.acc_mm_s2[k] = a * r_ * r_ + v * rd_;
        last_.jerk_mm_s3[k] = j * r_ * r_ * r_ + 3 * a * r_ * rd_ + v * rdd_;
    }
    last_.line = planned.line;
    if (tau_ > 0 && !is_action(cur)) enter_front();
    status_.action_pending = is_action(cur) && !action_done_;
    status_.block_paused =
        !status_.action_pending && tau_ >= cur.profile.duration_s && pauses_at_block_end(cur);
    bool at_end = status_.action_pending || status_.block_paused ||
                  (ring_.size() == 1 && tau_ >= cur.profile.duration_s);
    status_.done = at_end && cur.program_end && ring_.size() == 1 && !status_.action_pending;
    status_.starved = at_end && !cur.program_end && !status_.block_paused;
    if (at_end) {  // nothing left to follow: the rate no longer moves anything
        last_.vel_mm_s = {};
        last_.acc_mm_s2 = {};
        last_.jerk_mm_s3 = {};
    }
    status_.moving = !at_end && r_ > 0;
    status_.held = hold_ && r_ == 0 && rd_ == 0;
    status_.aborted = abort_ && r_ == 0 && rd_ == 0;
    status_.rate = r_;
    status_.braking = false;
    if (!abort_) check_block_end_brake();
    return last_;
}

}  // namespace motion
