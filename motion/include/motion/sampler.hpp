// Realtime side: samples prepared records once per servo period, applying feed override,
// feed hold and abort by scaling time.
//
// The sampler keeps its own clock tau in planned time and a rate r = d tau / dt (1 = as
// planned, 0 = stopped). With planned axis velocity v, acceleration a and jerk j at tau, the
// commanded motion is
//     velocity v r,   acceleration a r^2 + v r',   jerk j r^3 + 3 a r r' + v r''.
// The planner leaves `override_reserve` of each axis's acceleration and jerk unused (1 % by
// default), and the rate only changes in the room the plan itself leaves:
// - without a jerk limit (r'' free, so r' may differ from one period to the next) each period
//   takes the room of the stretch that period covers (room_limits(): the phases' peak speed and
//   acceleration against each axis's limit), in both directions; while slowing down the bounds
//   also grow as a r^2 shrinks (rate_limits_now());
// - with a jerk limit r' must stay continuous, so a rate change that looks fine now must also
//   be undoable in the room ahead. Each period proposes the time-optimal move towards the target
//   under bounds taken from the room of the stretch ahead (jerk_room_limits()), and accepts it
//   only if that move, followed by its backup (r' braked to 0, then r brought down to at most
//   1, then held; brake_path()), keeps every axis within its velocity, acceleration and jerk
//   limits over the part of every profile phase it covers (rate_path_safe(): per piece, the
//   smaller of two bounds on a r^2 + v r' and j r^3 + 3 a r r' + v r'': the plan's peaks
//   with the terms added, and the terms as signed ranges with an arc's perpendicular parts in
//   quadrature, ranged_axis_peak()). While slowing below 1, and while speeding up towards a
//   rate of at most 1 (directed_moves()), other moves are tried first, each with a backup
//   that brakes r' in pieces, each at the room of the stretch it covers, coasting while there
//   is none as a falling rate makes room (coast_backup()): r'' of the sign of the change at
//   the room the plan's jerk leaves on that side (signed_jerk_room(): inside a jerk phase at
//   r = 1 the side against the plan's jerk has nearly 2 J, the other 1 %; in cruise J), or
//   the least r'' that keeps the tangential jerk within the limit, as long as that backup
//   still lands on the near side of the target; speeding up, near the target, the
//   time-optimal move onto it at that room (approach()), and where the ramp's backup no
//   longer fits r' let down at a quarter of its r''; else that landing itself. So a hold
//   follows nearly the shortest jerk-limited stop, and a raise starts in the period it is
//   asked for wherever the plan leaves room. Otherwise the period follows the backup
//   accepted before (cert_), which stays valid because it was checked to its end. A rate held
//   at r <= 1 is a pure time scale, which the plan keeps within (1 - reserve) of every limit,
//   so the backup always ends safe; beyond the records in the ring only what the planner
//   guarantees of every record is trusted (unknown_safe(): the fixed bounds at r = 1, more as r
//   falls; rate_fits_any_record()). The rate then changes quickly where the plan leaves room
//   (cruise, r < 1, changing against the plan's jerk or its acceleration); slowing in a jerk
//   phase that ends an acceleration, the plan's own jerk already decelerates at the limit and
//   the rate rides it (what the axis's jerk limit allows anyway), and speeding up inside an
//   acceleration at nearly the limit the rate can only creep until the plan leaves room
//   (a r^2 + v r' within A). Above 1 only the symmetric proposal rises (the caps shape it).
// Above r = 1 the per-phase rate caps of the records within reach shape the target, and the
// checks above keep a r^2, j r^3 and v r within the limits. So any override in [0, max_rate],
// any hold and any abort keeps every axis within its limits.
//
// Two stops do not scale time but drive the path speed u directly:
// - fault_stop() (a drive fault, a limit switch, an e-stop) decelerates along the path at the
//   full acceleration the axes allow, ignoring the jerk limit (a line at a: stops within
//   u^2 / 2a), then discards the queue like abort();
// - single block: when the rest of the current block is just long enough for a stop at 80 % of
//   the deceleration and jerk limits, u follows the jerk-limited stop (jerk_stop.hpp) that lands
//   exactly on the block's end, re-solved every period. Without a jerk limit (or if the stop
//   started too late for one) it falls at the constant rate that lands there.
// Action records (prepared.hpp) are stood on until the owner calls action_done(); on a
// conditional move's record (G904) the sampler itself moves the axes meanwhile (ProbeJog). Digital
// outputs synchronised with motion ride on motion records (dout_set / dout_clear) and fall due
// in the period the sampler starts following their record; take_sync_outputs() collects them.
//
// Everything on this class is realtime-safe (noexcept, no allocation, bounded time) except
// the constructor. One thread drives advance(); the controls may be called from the same thread.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "motion/jerk_stop.hpp"
#include "motion/planner.hpp"
#include "motion/prepared.hpp"
#include "motion/probe_jog.hpp"
#include "motion/spsc_ring.hpp"
#include "motion/types.hpp"

namespace motion {

struct SamplerConfig {
    AxisLimits limits;
    double override_reserve = 0.01;  // must equal the planner's (override_reserve_in_effect())
    double max_rate = 1.2;          // must equal the planner's
    double junction_share = 0.1;    // must equal the planner's
    // Most records scanned for rate caps per period; also the size of the per-record cache the
    // constructor allocates (each record's derivative bounds and, jerk unlimited, its rooms are
    // computed once).
    std::size_t lookahead_records = 512;
};
SamplerConfig sampler_config(const PlannerConfig& p);

struct RateLimits {
    double max_rate_per_s = 0;   // |r'|
    double max_rate_per_s2 = 0;  // |r''|
};
// The largest |r'| and |r''| that fit in the reserve for these limits whatever the plan does
// (at r <= 1, or within the planner's rate caps).
RateLimits rate_limits(const SamplerConfig& cfg) noexcept;

// One piece of a jerk-limited rate move: r'' held at u for h seconds of wall time.
struct RatePiece {
    double u = 0;
    double h = 0;
    bool zero_rd = false;  // r' lands exactly on 0 at its end (rounding removed)
    double r_snap = -1;    // >= 0: r lands exactly on this at its end
};
// A short sequence of such pieces: a period's move, or the backup that follows it.
struct RatePath {
    static constexpr int kMaxPieces = 24;
    std::array<RatePiece, kMaxPieces> pieces{};
    int count = 0;
    void add(const RatePiece& p) noexcept {
        if (count < kMaxPieces) pieces[static_cast<std::size_t>(count++)] = p;
    }
};

// A rate path's piece as the checks see it: r and r' between lo and hi, r'' constant.
struct RateSpan {
    double r_lo = 0, r_hi = 0;
    double rd_lo = 0, rd_hi = 0;
    double rdd = 0;
};

// What axis k of an element with derivative bounds b sees at most while the plan runs profile
// phase `ph` over [t_lo, t_hi] of the phase's own time with the rate inside `rate`: the ranged
// bound of the jerk-limited checks (sampler.cpp), one of the two they take the smaller of.
// Realtime-safe; public for its tests.
struct AxisPeak {
    double acc_mm_s2 = 0, jerk_mm_s3 = 0;
};
AxisPeak ranged_axis_peak(const ElementBounds& b, int k, const ProfilePhase& ph, double t_lo,
                          double t_hi, const RateSpan& rate) noexcept;

// Whether a piece of a rate path with r, r', r'' within `box` keeps every axis within its
// limits whatever record the planner made, knowing only what the planner guarantees of every
// record (sampler.cpp): what the jerk-limited checks trust beyond the queued records. `fixed`
// is rate_limits(cfg). Realtime-safe; public for its tests.
bool rate_fits_any_record(const SamplerConfig& cfg, const RateLimits& fixed,
                          const RateSpan& box) noexcept;

struct SamplerStatus {
    bool moving = false;   // rate > 0 and a record is being followed
    bool done = false;     // at the end of a program_end record, nothing queued
    bool starved = false;  // ran out of records before a program_end: the producer fell behind
    bool held = false;     // hold requested and the rate has reached 0
    bool aborted = false;  // abort requested and the rate has reached 0; queue being discarded
    double rate = 0;       // current time scale r
    bool action_pending = false;  // standing on an action record not yet reported done
    bool block_paused = false;    // single block: at rest at a block's end, until resume_block()
    bool braking = false;         // a fault stop or a single-block stop is under way
};

class Sampler {
  public:
    Sampler(const SamplerConfig& cfg, SpscRing<PreparedSegment>& ring, const AxisArray& start_mm);

    void set_feed_override(double scale) noexcept;   // clamped to [0, max_rate]
    void set_rapid_override(double scale) noexcept;  // for rapid records; clamped likewise
    void set_hold(bool on) noexcept;
    void abort() noexcept;
    // After an abort has stopped: accept records again (the owner resets the planner first).
    void clear_abort() noexcept;
    // Abort with the shortest stop the acceleration limits allow (jerk ignored): for faults.
    void fault_stop() noexcept;
    // Single block: stop at the end of every block (a change of the records' source line).
    void set_single_block(bool on) noexcept;
    // Leaves a single-block pause: the next block runs.
    void resume_block() noexcept;
    // The action of the record being stood on, or null. Valid until the next advance().
    const Action* pending_action() const noexcept;
    // The owner has carried out the pending action: motion goes on with the next record.
    void action_done() noexcept;

    // The synchronised outputs of the records entered since the last call, in program order
    // (a later record's set or clear wins), then forgets them. Call once per period after
    // advance().
    struct SyncOutputs {
        std::uint64_t set = 0;
        std::uint64_t clear = 0;
        std::uint32_t message = 0;  // highest PreparedSegment::message entered; 0: none
    };
    SyncOutputs take_sync_outputs() noexcept;

    // The digital inputs (bit n = motion.digital-in-n) a conditional move watches; set them
    // every period before advance().
    void set_inputs(std::uint64_t bits) noexcept { inputs_ = bits; }
    // The conditional move (G904) of the action record stood on: it runs while its action is
    // pending; when finished() the owner reads the result and calls action_done().
    const ProbeJog& probe_jog() const noexcept { return jog_; }

    // Advances wall time by dt_s and returns the commanded motion at the new time.
    MotionSample advance(double dt_s) noexcept;

    const SamplerStatus& status() const noexcept { return status_; }

  private:
    double rate_target(double dt) noexcept;
    double current_override() const noexcept;
    double rate_cap_ahead() const noexcept;
    double rate_cap_free(double dt) noexcept;
    // lim: the axes' limits for the element's bounds, joint_space_ for joint_bounds().
    double phase_room(const ElementBounds& b, const AxisLimits& lim, const ProfilePhase& ph,
                      double t_s, double r_hi) const noexcept;
    struct WalkFrom {
        std::size_t index = 0;  // first ring record the walk may need
        double start_s = 0;     // its start in the front record's planned time
    };
    double advance_rate_jerk(double target, double dt) noexcept;
    // The directed moves towards `goal` (slowing, or speeding up to at most 1); true with the
    // planned time passed when one was taken.
    bool directed_moves(double goal, double dt, const RateLimits& room, double vm_acc,
                        double& passed) noexcept;
    bool approach(double goal, double dt, const RateLimits& lim, double& passed) noexcept;
    // `move` then `backup` passes the check: `backup` becomes the certificate and `after` the
    // limits the next periods' reach estimates take (the move itself is the caller's to apply).
    bool certify(const RatePath& move, const RatePath& backup, const RateLimits& after) noexcept;
    RateLimits jerk_room_limits(double target, double dt, double* vm_acc_out = nullptr) noexcept;
    bool rate_path_safe(const RatePath& path) noexcept;
    // The largest |r''| of each sign that keeps the tangential jerk j r^3 + 3 a r r' + v r''
    // within every axis's jerk limit over planned time [from, to] with r, r' within `box` (the
    // plan's signed terms, so an r'' against the plan's jerk gets the room that jerk leaves on
    // its other side); negative where none fits. A guess for the jerk-limited proposals and
    // backups: rate_path_safe() decides.
    struct SignedRoom {
        double up = 0, down = 0;          // largest |r''| for r'' > 0 and for r'' < 0
        double up_min = 0, down_min = 0;  // least |r''| of that sign (0: r'' = 0 fits)
        double rd_down = 0;  // largest |r'| for r' < 0 that keeps the acceleration within A
        double rd_up = 0;    // largest r' > 0 that keeps it within A
    };
    SignedRoom signed_jerk_room(double from, double to, const RateSpan& box, WalkFrom& at) noexcept;
    // The backup that brakes r' to 0 in pieces, each at the largest |r''| its own stretch
    // allows (signed_jerk_room()), coasting (r'' = 0) while there is none and the rate falls;
    // then, above 1, brings the rate down to 1. False when it cannot end within
    // RatePath::kMaxPieces pieces with r >= 0; r_end: the rate where r' reaches 0.
    bool coast_backup(double r, double rd, double tau, double am_hint, RatePath& out,
                      double& r_end) noexcept;
    // The phases of the ring's records over planned time [from, to] (front record's time) are
    // fine with the rate, its r' and r'' within `box` (sampler.cpp).
    bool stretch_safe(double from, double to, const RateSpan& box, WalkFrom& at) noexcept;
    // Beyond the ring: whether a piece keeps the limits whatever the plan there, and the
    // proposal's bounds for that.
    bool unknown_safe(const RateSpan& box) const noexcept;
    RateLimits unknown_room(double r_hi) const noexcept;
    double apply_rate(const RatePath& path) noexcept;
    enum class Walk : unsigned char { Covered, Stopped, Unknown };
    template <class Visit>
    Walk walk_phases(double from, double to, WalkFrom& at, Visit&& visit) noexcept;
    double integrate_rate_free(double target, double dt, double max_rate_per_s) noexcept;
    RateLimits rate_limits_now(double target, double dt) const noexcept;
    double room_rate(double from, double to, double r_hi) const noexcept;
    RateLimits room_limits(const RateLimits& base, double target, double dt) const noexcept;
    void consume_finished_records() noexcept;
    // Every pop of the ring goes through here, so the room cache stays aligned with the ring;
    // pop_front() also makes the record's synchronised outputs due, drop_front() (an abort's
    // discard) does not.
    void pop_front() noexcept;
    void drop_front() noexcept;
    // What the rate checks need of one record, computed once per record instead of once per
    // period (records never change in the ring): its derivative bounds and, without a jerk
    // limit, phase_room() of each phase at the highest rate (what rate_cap_free() needs).
    struct RecordCache {
        const PreparedSegment* rec = nullptr;  // the ring slot it was computed for (a guard)
        ElementBounds bounds{};
        ElementBounds joint_bounds{};  // the listed joints' (limits.hpp), when there are any
        std::array<double, kMaxPhases> room_per_s{};
    };
    const RecordCache& cached(std::size_t i) noexcept;
    void warm_rooms(std::size_t count) noexcept;
    bool pauses_at_block_end(const PreparedSegment& cur) const noexcept;
    enum class Brake : unsigned char { None, Fault, BlockEnd };
    void start_brake(Brake kind) noexcept;
    double decel_limit(const PreparedSegment& rec, double u) const noexcept;
    double block_remaining(double s_mm, bool* planned_stop) const noexcept;
    void land_at_block_end() noexcept;
    MotionSample brake_step(double dt) noexcept;
    double path_accel(const PathState& ps) const noexcept;
    double path_jerk_limit(const PreparedSegment& rec) const noexcept;
    bool jerk_brake(const PreparedSegment& cur, double left_mm, double dt,
                    JerkStopStep& step) const noexcept;
    void check_block_end_brake() noexcept;
    bool front_is_probe() const noexcept;
    MotionSample probe_step(double dt) noexcept;
    void enter_front() noexcept;

    SamplerConfig cfg_;
    // The listed joints' limits, joint j as axis j (limits.hpp): the checks written per axis run
    // once more over the joints' bounds with these.
    AxisLimits joint_space_;
    RateLimits rl_;           // fixed limits from the reserve
    RateLimits last_limits_;  // limits used in the last period
    RatePath cert_;           // jerk limited: the checked backup from the current (tau, r, r')
    SpscRing<PreparedSegment>& ring_;
    MotionSample last_{};
    double tau_ = 0;  // planned time within the front record
    double r_ = 1;    // rate
    double rd_ = 0;   // d rate / dt
    double rdd_ = 0;  // d^2 rate / dt^2 in effect
    double override_ = 1;
    double rapid_override_ = 1;
    bool hold_ = false;
    bool abort_ = false;
    bool jerk_limited_ = false;
    bool fault_ = false;
    bool single_block_ = false;
    bool block_released_ = false;  // resume_block() given at the current block end
    bool action_done_ = false;     // for the action record at the front
    Brake brake_ = Brake::None;
    double brake_s_mm_ = 0;       // position within the front record while braking
    double brake_u_mm_s_ = 0;     // path speed while braking
    double brake_a_mm_s2_ = 0;    // path acceleration while braking (single block's jerk stop)
    bool front_entered_ = false;  // the front record's synchronised outputs are due already
    SyncOutputs outputs_due_{};
    ProbeJog jog_;
    std::uint64_t inputs_ = 0;
    SamplerStatus status_{};
    // A ring over the first lookahead_records records: entry i of the ring is at
    // (rooms_head_ + i) % size; the first rooms_valid_ entries are filled.
    std::vector<RecordCache> rooms_;
    std::size_t rooms_head_ = 0;
    std::size_t rooms_valid_ = 0;
};

}  // namespace motion
