#include "motion/sampler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "motion/jerk_stop.hpp"

namespace motion {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
// Single block: braking for a block's end starts when the deceleration that lands on it reaches
// this share of the limit, leaving room for the speed the next period could still add.
constexpr double kBlockBrakeShare = 0.8;
// Without a jerk limit r'' is free; r' still ramps over this time so the rate stays smooth.
constexpr double kRateRampS = 0.005;
// Room cache entries filled per period ahead of need: more than the records a period can
// finish at the highest rate on short segments (0.05 mm at 120 mm/s: 2.4), so the cache is warm
// by the time the override rises, and the cost stays spread over the periods.
constexpr std::size_t kWarmRecordsPerPeriod = 8;

bool is_action(const PreparedSegment& rec) noexcept {
    return rec.action.kind != ActionKind::None;
}
}  // namespace

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
    const AxisLimits& lim = cfg.limits;
    for (int k = 0; k < kAxes; ++k) {
        vm = std::min(vm, eta * lim.acc_mm_s2[k] / lim.vel_mm_s[k]);
        if (lim.jerk_mm_s3[k] > 0) {
            vm = std::min(vm, eta / 2 * lim.jerk_mm_s3[k] / (3 * cfg.max_rate * lim.acc_mm_s2[k]));
            am = std::min(am, eta / 2 * lim.jerk_mm_s3[k] / lim.vel_mm_s[k]);
        }
    }
    // Without a jerk limit r'' is free; a 5 ms ramp of r' keeps the rate smooth anyway.
    if (!std::isfinite(am)) am = vm / kRateRampS;
    return {vm, am};
}

Sampler::Sampler(const SamplerConfig& cfg, SpscRing<PreparedSegment>& ring, const AxisArray& start)
    : cfg_(cfg),
      rl_(rate_limits(cfg)),
      last_limits_(rl_),
      ring_(ring),
      rooms_(std::max<std::size_t>(cfg.lookahead_records, 1)) {
    last_.pos_mm = start;
    jerk_limited_ = std::any_of(cfg.limits.jerk_mm_s3.begin(), cfg.limits.jerk_mm_s3.end(),
                                [](double j) { return j > 0; });
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
    double up = std::max(rd_, 0.0);
    double over = std::max(0.0, r_ + up * up / (2 * rl_.max_rate_per_s2) - 1);
    double t_down = up / rl_.max_rate_per_s2 + over / rl_.max_rate_per_s +
                    rl_.max_rate_per_s / rl_.max_rate_per_s2;
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

// Moves (r, r') towards (target, 0) for dt along the time-optimal path with |r'| and |r''|
// bounded, integrating exactly over its constant-r'' pieces; returns the planned time passed.
double Sampler::integrate_rate(double target, double dt, const RateLimits& lim) noexcept {
    const double vm = lim.max_rate_per_s, am = lim.max_rate_per_s2;
    double passed = 0, left = dt;
    for (int iter = 0; iter < 4 && left > 0; ++iter) {
        double d = target - r_;
        if (std::fabs(d) <= 1e-12 && std::fabs(rd_) <= 1e-9) {
            r_ = target;
            rd_ = 0;
            rdd_ = 0;
            passed += r_ * left;
            break;
        }
        double stop = rd_ * std::fabs(rd_) / (2 * am);
        double s = d - stop > 0 ? 1.0 : (d - stop < 0 ? -1.0 : (rd_ > 0 ? -1.0 : 1.0));
        double vp = s * std::min(vm, std::sqrt(std::max(0.0, s * d * am + rd_ * rd_ / 2)));
        double ta = std::max(0.0, (vp - rd_) / (s * am));
        double da = (vp * vp - rd_ * rd_) / (2 * s * am);
        double dc = vp * vp / (2 * s * am);
        double tb = vp != 0 ? std::max(0.0, (d - da - dc) / vp) : 0.0;
        double tc = std::fabs(vp) / am;
        const double pieces[3][2] = {{s * am, ta}, {0, tb}, {-s * am, tc}};
        bool finished = true;
        for (const auto& pc : pieces) {
            double u = pc[0], h = std::min(left, pc[1]);
            passed += r_ * h + rd_ * h * h / 2 + u * h * h * h / 6;
            r_ += rd_ * h + u * h * h / 2;
            rd_ += u * h;
            rdd_ = u;
            left -= h;
            if (h < pc[1]) {
                finished = false;
                break;
            }
        }
        if (finished) {  // landed on the target: remove the rounding drift
            r_ = target;
            rd_ = 0;
            rdd_ = 0;
        }
    }
    if (r_ < 0) r_ = 0;
    return std::max(passed, 0.0);
}

RateLimits Sampler::rate_limits_now(double target, double dt) const noexcept {
    // Slowing down from a rate <= 1 (hold, abort, override down): as r falls, a r^2 and j r^3
    // leave more of each axis's limits to the r' and r'' terms, and the planned axis speed
    // (bounded over the time it takes to change r') bounds v r' better than vmax does. Both
    // fixed reserve limits and these stay valid, so the larger of each is used.
    if (!(target < r_ && rd_ <= 0 && r_ <= 1)) return rl_;
    const AxisLimits& lim = cfg_.limits;
    const double keep = 1 - cfg_.override_reserve;
    MotionSample now = sample(ring_.peek(0), tau_);
    double horizon = dt + last_limits_.max_rate_per_s / last_limits_.max_rate_per_s2;
    double vm = kInf, am = kInf;
    for (int k = 0; k < kAxes; ++k) {
        double vk = std::fabs(now.vel_mm_s[k]) + lim.acc_mm_s2[k] * r_ * horizon;
        if (vk <= 0) continue;
        // Next to an unblended kink the plan uses keep - junction_share and the kink's velocity
        // step (junction_share of a period's acceleration) scales with r, not r^2.
        const double js = cfg_.junction_share;
        const double used = std::max(keep * r_ * r_, (keep - js) * r_ * r_ + js * r_);
        vm = std::min(vm, lim.acc_mm_s2[k] * (1 - used) / vk);
        if (lim.jerk_mm_s3[k] > 0) {
            double free_jerk = lim.jerk_mm_s3[k] * (1 - keep * r_ * r_ * r_);
            if (r_ > 0) vm = std::min(vm, free_jerk / (2 * 3 * keep * lim.acc_mm_s2[k] * r_));
            am = std::min(am, free_jerk / (2 * vk));
        }
    }
    if (!std::isfinite(vm)) return rl_;
    if (!jerk_limited_) am = vm / kRateRampS;
    return {std::max(vm, rl_.max_rate_per_s), std::max(am, rl_.max_rate_per_s2)};
}

namespace {
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
}  // namespace

// Largest |r'| for which a r^2 + v r' stays within every axis's limit on one profile phase
// (duration t_s) of a record with derivative bounds b, at rates up to r_hi: axis k sees at most
// a_peak g1_k + v_peak^2 g2_k and v_peak g1_k. An unblended kink steps the velocity by up to
// junction_share of a period's acceleration (the planner's budget for it), scaled by the rate:
// that share is kept out of the room. Infinite where nothing moves.
double Sampler::phase_room(const ElementBounds& b, const ProfilePhase& ph, double t_s,
                           double r_hi) const noexcept {
    const AxisLimits& lim = cfg_.limits;
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
            for (int ph = 0; ph < p.count; ++ph) {
                const double t0 = p.phases[ph].t0_s;
                const double t1 = ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s;
                if (start + t1 < from || start + t0 > to) continue;
                best = std::min(best, phase_room(b, p.phases[ph], t1 - t0, r_hi));
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
            const PhaseRooms& rooms = rooms_of(i);
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

// The rooms of ring record i (i < lookahead_records), filling the entries up to it first. The
// phase durations are the record's own (t1 - t0 within the record), so the value does not
// depend on where the record sits in the queue.
const Sampler::PhaseRooms& Sampler::rooms_of(std::size_t i) noexcept {
    const std::size_t size = rooms_.size();
    if (i < rooms_valid_ && rooms_[(rooms_head_ + i) % size].rec != &ring_.peek(i))
        rooms_valid_ = i;  // the ring was popped behind our back: refill from here
    for (; rooms_valid_ <= i; ++rooms_valid_) {
        const std::size_t j = rooms_valid_;
        PhaseRooms& e = rooms_[(rooms_head_ + j) % size];
        const PreparedSegment& rec = ring_.peek(j);
        e.rec = &rec;
        e.room_per_s.fill(kInf);
        if (is_action(rec)) continue;  // stood on, never scaled
        const Profile1D& p = rec.profile;
        const ElementBounds b = bounds(rec.geom);
        for (int ph = 0; ph < p.count; ++ph) {
            const double t0 = p.phases[ph].t0_s;
            const double t1 = ph + 1 < p.count ? p.phases[ph + 1].t0_s : p.duration_s;
            e.room_per_s[ph] = phase_room(b, p.phases[ph], t1 - t0, cfg_.max_rate);
        }
    }
    return rooms_[(rooms_head_ + i) % size];
}

// Fills up to `count` more entries, so that raising the override above 100 % does not find
// the whole look-ahead to compute in one period.
void Sampler::warm_rooms(std::size_t count) noexcept {
    const std::size_t n = std::min(ring_.size(), rooms_.size());
    const std::size_t upto = std::min(n, rooms_valid_ + count);
    if (upto > 0 && upto > rooms_valid_) rooms_of(upto - 1);
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
        tau_ -= cur.profile.duration_s;
        pop_front();
    }
}

// The tangential deceleration that keeps every axis within its acceleration limit at path
// speed u on this record (the centripetal part u^2 p'' taken off first), never below 5 % of it.
double Sampler::decel_limit(const PreparedSegment& rec, double u) const noexcept {
    const ElementBounds b = bounds(rec.geom);
    double a = kInf, floor = kInf;
    for (int k = 0; k < kAxes; ++k) {
        if (b.g1[k] <= 1e-12) continue;
        const double acc = cfg_.limits.acc_mm_s2[k];
        a = std::min(a, (acc - u * u * b.g2[k]) / b.g1[k]);
        floor = std::min(floor, 0.05 * acc / b.g1[k]);
    }
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
    for (int k = 0; k < kAxes; ++k)
        if (b.g1[k] > 1e-12 && cfg_.limits.jerk_mm_s3[k] > 0)
            j = std::min(j, cfg_.limits.jerk_mm_s3[k] / b.g1[k]);
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
    PathState now = ring_.peek(0).profile.at(tau_);
    if (now.v_mm_s == 0 && (now.a_mm_s2 == 0 || !jerk_limited_)) {
        // At rest the rate has nothing to scale yet: take the target at once.
        r_ = target;
        rd_ = rdd_ = 0;
    }
    last_limits_ = rate_limits_now(target, dt);
    if (jerk_limited_) {
        tau_ += integrate_rate(target, dt, last_limits_);
    } else {
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
