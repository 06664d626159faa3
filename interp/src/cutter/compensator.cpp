// The streaming compensator: a one-move look-ahead state machine.
//
//   off ──(line with G41/G42)──▶ start-up ──(next move)──▶ contour ─┐
//    ▲                              │                       ▲  │ join │
//    │                              ▼                       └──┴──────┘
//    └──────(line with G40)──── cancel ◀──── resume ◀─ side/radius change,
//                                                      look-ahead exhausted
//
// "pending" is the last compensated move whose end is not yet known; its end
// is fixed by the corner it makes with the next move (join), by the cancel
// (perpendicular end), or by running out of look-ahead.

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "offset_geometry.hpp"

namespace interp::cutter {

using geom::Curve;
using geom::Segment;

namespace {

constexpr double kSamePointMm = 1e-9;
constexpr double kParallel = 1e-9;  // |sin| of a turn treated as straight or reversed

double side_sign(Side side) {
    return side == Side::Left ? 1.0 : -1.0;
}

Vec2 sample(const OutMove& m, double t) {
    if (m.shape == Shape::Line) return m.start + (m.end - m.start) * t;
    const Vec2 r0 = m.start - m.centre;
    const double a = std::atan2(r0.y(), r0.x()) + (m.ccw ? 1.0 : -1.0) * m.sweep_rad * t;
    return m.centre + r0.norm() * Vec2(std::cos(a), std::sin(a));
}

/// Axis-aligned bounds; arcs use their whole circle (cheap and conservative).
struct Box {
    Vec2 lo;
    Vec2 hi;
};

Box bounds(const Vec2& a, const Vec2& b) {
    return {a.cwiseMin(b), a.cwiseMax(b)};
}

Box bounds(const OutMove& m) {
    if (m.shape == Shape::Line) return bounds(m.start, m.end);
    const double r = (m.start - m.centre).norm();
    return {m.centre - Vec2(r, r), m.centre + Vec2(r, r)};
}

Box bounds(const Segment& s) {
    if (s.shape == Shape::Line) return bounds(s.start, s.end);
    return {s.centre - Vec2(s.radius, s.radius), s.centre + Vec2(s.radius, s.radius)};
}

double box_distance(const Box& a, const Box& b) {
    const Vec2 gap = (a.lo - b.hi).cwiseMax(b.lo - a.hi).cwiseMax(Vec2::Zero());
    return gap.norm();
}

bool full_circle(const Curve& c) {
    return c.shape == Shape::Arc && c.sweep >= 2.0 * std::numbers::pi - 1e-12;
}

}  // namespace

struct Compensator::Pending {
    enum class Kind { StartUp, Contour, Resume };
    struct Recent {
        Segment seg;
        SourceTag tag;
        Box box;
    };
    Kind kind = Kind::StartUp;
    Segment seg;                     // the programmed move (StartUp: the start-up line)
    Curve curve;                     // Contour: its offset
    double u_start = 0;              // Contour: where the offset starts after the previous corner
    Move move;                       // the block itself (side, radius, plane, tag, rapid)
    SourceTag on_tag{};              // the block that switched compensation (or its side) on
    std::vector<Recent> recent;      // the last contour moves, for the gouge check
    std::optional<Recent> upcoming;  // the move being joined, while its corner is emitted
    // Moves after this one too short for the tool at an inside corner: they get no offset piece;
    // the next move that leaves room joins this one directly (see join_after_skip).
    std::vector<Recent> skipped;
    // The previous move, whose piece up to its inside corner with this move is not emitted yet:
    // this move's offset is shorter than r after that corner, so the next corner may consume it
    // from its start, and then the previous move is joined to the next one directly.
    struct Deferred {
        OutMove piece;
        Segment seg;
        Curve curve;
        double u_start = 0;
        Move move;
    };
    std::optional<Deferred> deferred;

    void become_contour(const Segment& s, const Curve& c, double u, const Move& m, SourceTag on,
                        std::size_t window) {
        kind = Kind::Contour;
        seg = s;
        curve = c;
        u_start = u;
        move = m;
        on_tag = on;
        upcoming.reset();
        skipped.clear();
        deferred.reset();
        remember(Recent{s, m.tag, bounds(s)}, window);
    }

    void remember(const Recent& r, std::size_t window) {
        recent.push_back(r);
        if (recent.size() > window) recent.erase(recent.begin(), recent.end() - window);
    }
};

Compensator::Compensator(Config config, Vec2 start, double start_h)
    : config_(config), programmed_(start), programmed_h_(start_h), tool_(start), tool_h_(start_h) {}
Compensator::~Compensator() = default;
Compensator::Compensator(Compensator&&) noexcept = default;
Compensator& Compensator::operator=(Compensator&&) noexcept = default;

Compensator::Compensator(const Compensator& other)
    : config_(other.config_),
      programmed_(other.programmed_),
      programmed_h_(other.programmed_h_),
      tool_(other.tool_),
      tool_h_(other.tool_h_),
      last_tag_(other.last_tag_),
      current_tag_(other.current_tag_),
      pending_(other.pending_ ? std::make_unique<Pending>(*other.pending_) : nullptr),
      held_(other.held_),
      held_moves_(other.held_moves_),
      out_(other.out_) {}

Compensator& Compensator::operator=(const Compensator& other) {
    if (this == &other) return *this;
    config_ = other.config_;
    programmed_ = other.programmed_;
    programmed_h_ = other.programmed_h_;
    tool_ = other.tool_;
    tool_h_ = other.tool_h_;
    last_tag_ = other.last_tag_;
    current_tag_ = other.current_tag_;
    // Assigning into the existing Pending keeps its vector's capacity: no allocation per block.
    if (!other.pending_)
        pending_.reset();
    else if (pending_)
        *pending_ = *other.pending_;
    else
        pending_ = std::make_unique<Pending>(*other.pending_);
    held_ = other.held_;
    held_moves_ = other.held_moves_;
    out_ = other.out_;
    return *this;
}

std::optional<SourceTag> Compensator::held_move() const {
    if (!pending_) return std::nullopt;
    return pending_->move.tag;
}

namespace {

std::string compose(const std::string& reason, SourceTag earlier, SourceTag at,
                    const std::optional<SourceTag>& contour, const std::string& tail,
                    const CompError::Namer& name) {
    std::string text = reason;
    if (contour) text += fmt::format(" {}{}", name(*contour), tail);
    if (earlier != at) text += fmt::format(" (with the move at {})", name(earlier));
    return text;
}

// what() names blocks by their tags, for callers whose tags are line numbers.
std::string tag_as_line(SourceTag t) {
    return fmt::format("line {}", t);
}

}  // namespace

CompError::CompError(std::string reason_text, SourceTag earlier, SourceTag at,
                     std::optional<SourceTag> contour, std::string tail_text)
    : std::runtime_error(compose(reason_text, earlier, at, contour, tail_text, tag_as_line)),
      reason(std::move(reason_text)),
      earlier_block(earlier),
      at_block(at),
      contour_block(contour),
      tail(std::move(tail_text)) {}

std::string CompError::message(const Namer& name) const {
    return compose(reason, earlier_block, at_block, contour_block, tail, name);
}

void Compensator::set_position(const Vec2& position, double h) {
    if (pending_ || !held_.empty())
        throw CompError(
            "cutter comp: the position cannot be redefined while compensation is active",
            pending_ ? pending_->move.tag : last_tag_.value_or(0), last_tag_.value_or(0));
    programmed_ = tool_ = position;
    programmed_h_ = tool_h_ = h;
}

std::vector<Output> Compensator::drain() {
    std::vector<Output> out;
    out.swap(out_);
    return out;
}

void Compensator::push(const Marker& marker) {
    current_tag_ = marker.tag;
    if (pending_)
        held_.emplace_back(marker);
    else
        out_.emplace_back(OutMarker{marker.tag});
}

void Compensator::push(const Move& programmed) {
    // CRC-7: a negative radius swaps G41 and G42.
    Move move = programmed;
    current_tag_ = move.tag;
    if (move.radius_mm < 0) {
        move.radius_mm = -move.radius_mm;
        if (move.side != Side::Off) move.side = move.side == Side::Left ? Side::Right : Side::Left;
    }
    const Segment seg = Segment::make(programmed_, programmed_h_, move);
    if (pending_ && move.plane != pending_->move.plane)
        throw CompError(fmt::format("cutter comp: the plane changed from G{} to G{} while "
                                    "compensation is active",
                                    pending_->move.plane, move.plane),
                        pending_->move.tag, move.tag);
    if (seg.degenerate()) {
        push_no_plane_motion(move);
    } else if (!pending_) {
        if (move.side == Side::Off)
            push_plain(move);
        else
            start_up(move);
    } else if (move.side == Side::Off) {
        cancel(move);
    } else if (pending_->kind == Pending::Kind::Resume || move.side != pending_->move.side ||
               move.radius_mm != pending_->move.radius_mm) {
        end_pending_perpendicular();
        link(move);
    } else if (pending_->kind == Pending::Kind::StartUp) {
        finish_start_up(move);
    } else {
        join(move);
    }
    programmed_ = move.end;
    programmed_h_ = move.end_h;
    last_tag_ = move.tag;
}

void Compensator::finish() {
    if (pending_) {
        const SourceTag tag = pending_->move.tag;
        end_pending_perpendicular();
        pending_.reset();
        out_.emplace_back(OutWarning{
            "cutter comp: compensation still active at program end; cancelled without a move",
            tag});
    }
    flush_held();
}

void Compensator::push_plain(const Move& move) {
    const Segment seg = Segment::make(programmed_, programmed_h_, move);
    OutMove m;
    m.shape = move.shape;
    m.start = tool_;
    m.end = move.end;
    m.start_h = tool_h_;
    m.end_h = move.end_h;
    if (move.shape == Shape::Arc) {
        m.centre = move.centre;
        m.ccw = move.ccw;
        m.sweep_rad = seg.sweep;
    }
    m.rapid = move.rapid;
    m.role = Role::Plain;
    m.tag = move.tag;
    out_.emplace_back(m);
    tool_ = move.end;
    tool_h_ = move.end_h;
}

void Compensator::push_no_plane_motion(const Move& move) {
    if (!pending_) {
        emit_line(tool_, move.end_h, move.rapid, Role::Plain, move.tag);
        return;
    }
    if (move.side == Side::Off) {
        // G40 in a block without plane motion cancels in that block: the tool
        // returns from the perpendicular to the programmed point.
        end_pending_perpendicular();
        pending_.reset();
        emit_line(programmed_, move.end_h, move.rapid, Role::Cancel, move.tag);
        return;
    }
    held_.emplace_back(move);
    if (++held_moves_ <= config_.lookahead_moves) return;
    if (config_.on_exhausted == OnLookaheadExhausted::Error)
        throw CompError(fmt::format("cutter comp: more than {} blocks without motion in the "
                                    "compensation plane",
                                    config_.lookahead_moves),
                        pending_->move.tag, move.tag);
    end_pending_perpendicular();
}

namespace {

/// `before` is the block ahead of `move` (the held move, or the start-up block).
Curve offset_or_throw(const Segment& seg, const Move& move, SourceTag before) {
    const auto curve = geom::offset(seg, side_sign(move.side) * move.radius_mm);
    if (!curve)
        throw CompError(fmt::format("cutter comp: the tool radius {:g} does not fit the inside arc "
                                    "of radius {:g}",
                                    move.radius_mm, seg.radius),
                        before, move.tag);
    return *curve;
}

/// The intersection of two offset curves nearest the programmed corner that lies
/// on what is left of the first (from u_start) and on the second: (u on a, u on b).
std::optional<std::pair<double, double>> inside_joint(const Curve& a, double a_u_start,
                                                      const Curve& b, const Vec2& corner) {
    std::optional<std::pair<double, double>> best;
    double best_dist = 0.0;
    for (const Vec2& p : geom::intersections(a, b)) {
        double ua = a.param(p);
        if (full_circle(a) && ua <= a.tol_u()) ua = 1.0;
        const double ub = b.param(p);
        const bool on_a = ua >= a_u_start - a.tol_u() && ua <= 1.0 + a.tol_u();
        const bool on_b = ub >= -b.tol_u() && ub <= 1.0 + b.tol_u();
        const double dist = (p - corner).norm();
        if (on_a && on_b && (!best || dist < best_dist)) {
            best = std::make_pair(std::clamp(ua, a_u_start, 1.0), std::clamp(ub, 0.0, 1.0));
            best_dist = dist;
        }
    }
    return best;
}

void check_reversal(const Vec2& t_in, const Vec2& t_out, SourceTag a, SourceTag b) {
    if (std::abs(geom::cross(t_in, t_out)) <= kParallel && t_in.dot(t_out) < 0)
        throw CompError("cutter comp: path reversal", a, b);
}

}  // namespace

void Compensator::start_up(const Move& move) {
    if (move.shape == Shape::Arc) {
        const SourceTag before = last_tag_.value_or(move.tag);
        throw CompError("cutter comp: compensation cannot start on an arc; start it with G00/G01",
                        before, move.tag);
    }
    pending_ = std::make_unique<Pending>();
    pending_->kind = Pending::Kind::StartUp;
    pending_->seg = Segment::make(programmed_, programmed_h_, move);
    pending_->move = move;
    pending_->on_tag = move.tag;
}

void Compensator::finish_start_up(const Move& move) {
    const Segment seg = Segment::make(programmed_, programmed_h_, move);
    const Curve curve = offset_or_throw(seg, move, pending_->move.tag);
    // S0 §3.5.3: the start-up block ends on the perpendicular at the next block's start.
    emit_line(curve.at(0), pending_->seg.h1, pending_->move.rapid, Role::Startup,
              pending_->move.tag);
    flush_held();
    pending_->become_contour(seg, curve, 0.0, move, pending_->on_tag, config_.gouge_check_moves);
}

void Compensator::link(const Move& move) {
    const Segment seg = Segment::make(programmed_, programmed_h_, move);
    const SourceTag on_tag = move.side != pending_->move.side ? move.tag : pending_->on_tag;
    const Curve curve = offset_or_throw(seg, move, pending_->move.tag);
    emit_line(curve.at(0), seg.h0, move.rapid, Role::Startup, move.tag);
    pending_->become_contour(seg, curve, 0.0, move, on_tag, config_.gouge_check_moves);
}

void Compensator::join(const Move& move) {
    Pending& a = *pending_;
    const Segment seg = Segment::make(programmed_, programmed_h_, move);
    const Curve next = offset_or_throw(seg, move, a.move.tag);
    a.upcoming = Pending::Recent{seg, move.tag, bounds(seg)};
    if (!a.skipped.empty()) {
        join_after_skip(seg, next, move);
        return;
    }
    if (a.deferred && consumed_from_start(seg, next, move)) {
        // The held move has no room left: the deferred move takes its place and it is skipped.
        Pending::Deferred d = std::move(*a.deferred);
        const Pending::Recent held{a.seg, a.move.tag, bounds(a.seg)};
        a.deferred.reset();
        a.seg = d.seg;
        a.curve = d.curve;
        a.u_start = d.u_start;
        a.move = d.move;
        a.skipped.push_back(held);
        join_after_skip(seg, next, move);
        return;
    }
    emit_deferred();
    const Vec2 t_in = a.seg.tangent(1.0);
    const Vec2 t_out = seg.tangent(0.0);
    const double turn_sin = geom::cross(t_in, t_out);
    check_reversal(t_in, t_out, a.move.tag, move.tag);

    const double r = move.radius_mm;
    const double s = side_sign(move.side);
    double u_next = 0.0;
    if (r == 0.0 || std::abs(turn_sin) <= kParallel) {
        emit_piece(a.curve.piece(a.u_start, 1.0), a.move.rapid, Role::Contour, a.move.tag);
    } else if (s * turn_sin > 0) {
        // Inside corner: trim both offsets to their intersection nearest the
        // corner, which must lie within what is left of each move.
        const auto best = inside_joint(a.curve, a.u_start, next, seg.start);
        if (!best) {
            if (!can_skip(next)) throw corner_gouge(a.move.tag, move.tag);
            skip(seg, move);
            return;
        }
        u_next = best->second;
        if (should_defer(next, u_next)) {
            Pending::Deferred d{a.curve.piece(a.u_start, best->first), a.seg, a.curve, a.u_start,
                                a.move};
            a.become_contour(seg, next, u_next, move, a.on_tag, config_.gouge_check_moves);
            a.deferred = std::move(d);
            return;
        }
        emit_piece(a.curve.piece(a.u_start, best->first), a.move.rapid, Role::Contour, a.move.tag);
    } else {
        // Outside corner: go around the corner point at distance r.
        emit_piece(a.curve.piece(a.u_start, 1.0), a.move.rapid, Role::Contour, a.move.tag);
        const Vec2 from = tool_;
        const Vec2 to = next.at(0.0);
        const double turn = std::atan2(std::abs(turn_sin), t_in.dot(t_out));
        const double extend_max = config_.extend_max_turn_deg * std::numbers::pi / 180.0;
        const auto knee = geom::line_line(from, t_in, to, t_out);
        if (turn <= extend_max && knee) {
            emit_line(*knee, tool_h_, move.rapid, Role::Corner, move.tag);
            emit_line(to, tool_h_, move.rapid, Role::Corner, move.tag);
        } else {
            OutMove arc;
            arc.shape = Shape::Arc;
            arc.start = from;
            arc.end = to;
            arc.centre = seg.start;
            arc.ccw = turn_sin > 0;
            arc.sweep_rad = turn;
            arc.start_h = arc.end_h = tool_h_;
            emit_piece(arc, move.rapid, Role::Corner, move.tag);
        }
    }
    flush_held();
    a.become_contour(seg, next, u_next, move, a.on_tag, config_.gouge_check_moves);
}

// Deferring needs the gouge check (it proves the later joint) and nothing held between the two
// moves (a Z move there must run at the corner, before the next move's piece).
bool Compensator::should_defer(const Curve& next, double u_next) const {
    if (config_.gouge_check_moves == 0 || !held_.empty() || full_circle(next)) return false;
    const double length = next.shape == Shape::Line ? next.len : next.radius * next.sweep;
    return (1.0 - u_next) * length < pending_->move.radius_mm;
}

void Compensator::emit_deferred() {
    Pending& a = *pending_;
    if (!a.deferred) return;
    const Pending::Deferred d = std::move(*a.deferred);
    a.deferred.reset();
    emit_piece(d.piece, d.move.rapid, Role::Contour, d.move.tag);
}

// At an inside corner after the held move: its offset and the next one cross before what is left
// of the held move's offset (the previous corner already used it up).
bool Compensator::consumed_from_start(const Segment& seg, const Curve& next,
                                      const Move& move) const {
    const Pending& a = *pending_;
    const double turn_sin = geom::cross(a.seg.tangent(1.0), seg.tangent(0.0));
    if (side_sign(move.side) * turn_sin <= kParallel) return false;
    if (inside_joint(a.curve, a.u_start, next, seg.start)) return false;
    for (const Vec2& p : geom::intersections(a.curve, next)) {
        const double ua = a.curve.param(p);
        const double un = next.param(p);
        if (ua < a.u_start && un >= -next.tol_u() && un <= 1.0 + next.tol_u()) return true;
    }
    return false;
}

CompError Compensator::corner_gouge(SourceTag earlier, SourceTag at) const {
    return CompError(fmt::format("cutter comp: gouge: the tool radius {:g} does not fit the inside "
                                 "corner",
                                 pending_->move.radius_mm),
                     earlier, at);
}

// A move is skipped when the offsets of the held move and of this one cross beyond this one's
// end: the tool cannot touch it without cutting the held move. Only with the gouge check on,
// which proves the tool then stays at least r from the skipped move (else: a gouge error).
bool Compensator::can_skip(const Curve& next) const {
    const Pending& a = *pending_;
    if (config_.gouge_check_moves == 0 || a.skipped.size() >= config_.lookahead_moves ||
        full_circle(next))
        return false;
    for (const Vec2& p : geom::intersections(a.curve, next)) {
        const double ua = a.curve.param(p);
        if (ua >= a.u_start - a.curve.tol_u() && ua <= 1.0 + a.curve.tol_u() &&
            next.param(p) > 1.0 + next.tol_u())
            return true;
    }
    return false;
}

void Compensator::skip(const Segment& seg, const Move& move) {
    Pending& a = *pending_;
    const Pending::Recent r{seg, move.tag, bounds(seg)};
    a.skipped.push_back(r);
    a.remember(r, config_.gouge_check_moves);
    a.upcoming.reset();
}

// The held move meets the first move after the skipped ones. At an inside (or straight) corner
// after the last skipped move their offsets are trimmed to their crossing; at an outside corner
// the tool leaves the held move's offset where it comes within r of the corner point, and goes
// round that point to the next move's offset (the transition circle of S2 §3.4.4).
void Compensator::join_after_skip(const Segment& seg, const Curve& next, const Move& move) {
    Pending& a = *pending_;
    emit_deferred();
    const Pending::Recent& last = a.skipped.back();
    const Vec2 t_in = last.seg.tangent(1.0);
    const Vec2 t_out = seg.tangent(0.0);
    check_reversal(t_in, t_out, last.tag, move.tag);
    const double turn_sin = geom::cross(t_in, t_out);
    const double r = move.radius_mm;
    double u_next = 0.0;
    if (side_sign(move.side) * turn_sin > -kParallel) {
        const auto best = inside_joint(a.curve, a.u_start, next, seg.start);
        if (!best) {
            if (!can_skip(next)) throw corner_gouge(a.move.tag, move.tag);
            skip(seg, move);
            return;
        }
        emit_piece(a.curve.piece(a.u_start, best->first), a.move.rapid, Role::Contour, a.move.tag);
        u_next = best->second;
    } else {
        const Vec2 corner = seg.start;
        std::optional<double> first;
        Curve circle;
        circle.shape = Shape::Arc;
        circle.centre = corner;
        circle.radius = r;
        for (const Vec2& p : geom::intersections(a.curve, circle)) {
            const double ua = a.curve.param(p);
            if (ua >= a.u_start - a.curve.tol_u() && ua <= 1.0 + a.curve.tol_u() &&
                (!first || ua < *first))
                first = std::clamp(ua, a.u_start, 1.0);
        }
        if (!first) throw corner_gouge(a.move.tag, move.tag);
        emit_piece(a.curve.piece(a.u_start, *first), a.move.rapid, Role::Contour, a.move.tag);
        OutMove arc;
        arc.shape = Shape::Arc;
        arc.start = tool_;
        arc.end = next.at(0.0);
        arc.centre = corner;
        arc.ccw = turn_sin > 0;
        const Vec2 v0 = arc.start - corner, v1 = arc.end - corner;
        double sweep = std::atan2(geom::cross(v0, v1), v0.dot(v1));
        if (!arc.ccw) sweep = -sweep;
        if (sweep < 0) sweep += 2.0 * std::numbers::pi;
        arc.sweep_rad = sweep;
        arc.start_h = arc.end_h = tool_h_;
        emit_piece(arc, move.rapid, Role::Corner, move.tag);
    }
    flush_held();
    a.become_contour(seg, next, u_next, move, a.on_tag, config_.gouge_check_moves);
}

void Compensator::cancel(const Move& move) {
    if (!pending_->skipped.empty()) throw corner_gouge(pending_->move.tag, move.tag);
    if (move.shape == Shape::Arc)
        throw CompError(
            "cutter comp: compensation cannot be cancelled on an arc; cancel it with G00/G01",
            pending_->move.tag, move.tag);
    if (pending_->kind == Pending::Kind::Contour) {
        Pending& a = *pending_;
        const Segment seg = Segment::make(programmed_, programmed_h_, move);
        const Vec2 t_in = a.seg.tangent(1.0);
        const Vec2 t_out = seg.tangent(0.0);
        check_reversal(t_in, t_out, a.move.tag, move.tag);
        // CRC-10 (ISO): at an inside corner the perpendicular end would cut into
        // the cancel move's side, so stop where the offsets of both moves cross; a
        // cancel move too short for that leaves from the perpendicular.
        const double turn_sin = geom::cross(t_in, t_out);
        if (config_.cancel_at_inside_corner == CancelCorner::Intersection && a.move.radius_mm > 0 &&
            side_sign(a.move.side) * turn_sin > kParallel) {
            const auto exit_offset = geom::offset(seg, side_sign(a.move.side) * a.move.radius_mm);
            const auto joint = inside_joint(a.curve, a.u_start, *exit_offset, seg.start);
            if (joint) {
                emit_deferred();
                emit_piece(a.curve.piece(a.u_start, joint->first), a.move.rapid, Role::Contour,
                           a.move.tag);
                a.kind = Pending::Kind::Resume;
                flush_held();
            }
        }
    }
    end_pending_perpendicular();
    pending_.reset();
    emit_line(move.end, move.end_h, move.rapid, Role::Cancel, move.tag);
}

void Compensator::end_pending_perpendicular() {
    Pending& p = *pending_;
    // Skipped moves need the next move to place the corner; there is none.
    if (!p.skipped.empty()) throw corner_gouge(p.move.tag, current_tag_);
    switch (p.kind) {
        case Pending::Kind::StartUp: {
            const Vec2 t = p.seg.tangent(1.0);
            const Vec2 left(-t.y(), t.x());
            emit_line(p.seg.end + left * (side_sign(p.move.side) * p.move.radius_mm), p.seg.h1,
                      p.move.rapid, Role::Startup, p.move.tag);
            break;
        }
        case Pending::Kind::Contour:
            emit_deferred();
            emit_piece(p.curve.piece(p.u_start, 1.0), p.move.rapid, Role::Contour, p.move.tag);
            break;
        case Pending::Kind::Resume:
            break;
    }
    flush_held();
    p.kind = Pending::Kind::Resume;
}

void Compensator::flush_held() {
    for (const Held& h : held_) {
        if (const auto* m = std::get_if<Move>(&h))
            emit_line(tool_, m->end_h, m->rapid, Role::Height, m->tag);
        else
            out_.emplace_back(OutMarker{std::get<Marker>(h).tag});
    }
    held_.clear();
    held_moves_ = 0;
}

void Compensator::emit_line(const Vec2& to, double to_h, bool rapid, Role role, SourceTag tag) {
    if ((to - tool_).norm() <= kSamePointMm && std::abs(to_h - tool_h_) <= kSamePointMm) return;
    OutMove m;
    m.start = tool_;
    m.end = to;
    m.start_h = tool_h_;
    m.end_h = to_h;
    m.rapid = rapid;
    m.role = role;
    m.tag = tag;
    out_.emplace_back(m);
    tool_ = to;
    tool_h_ = to_h;
}

void Compensator::check_gouge(const OutMove& piece, double radius_mm) const {
    constexpr double kToleranceMm = 1e-6;
    // Samples about every r/10 along the piece, 4…256: dense CAM output of short
    // moves stays cheap, and a bump narrower than that is far below the radius.
    const double length = piece.shape == Shape::Arc
                              ? (piece.start - piece.centre).norm() * piece.sweep_rad
                              : (piece.end - piece.start).norm();
    const int samples = static_cast<int>(
        std::clamp(std::ceil(length / (0.1 * std::max(radius_mm, 1e-3))), 4.0, 256.0));
    const Box box = bounds(piece);
    const double h_lo = std::min(piece.start_h, piece.end_h) - 1e-9;
    const double h_hi = std::max(piece.start_h, piece.end_h) + 1e-9;
    auto check = [&](const Pending::Recent& r) {
        // Moves at other heights (a contour repeated deeper) are not in this layer.
        if (std::max(r.seg.h0, r.seg.h1) < h_lo || std::min(r.seg.h0, r.seg.h1) > h_hi) return;
        if (box_distance(box, r.box) >= radius_mm) return;
        double nearest = radius_mm;
        for (int i = 0; i <= samples; ++i)
            nearest =
                std::min(nearest, r.seg.distance(sample(piece, static_cast<double>(i) / samples)));
        if (nearest < radius_mm - kToleranceMm)
            throw CompError(fmt::format("cutter comp: gouge: the tool (radius {:g}) would come "
                                        "within {:.4g} of the contour of",
                                        radius_mm, nearest),
                            pending_->move.tag, current_tag_, r.tag);
    };
    for (const auto& r : pending_->recent) check(r);
    if (pending_->upcoming) check(*pending_->upcoming);
}

void Compensator::emit_piece(OutMove piece, bool rapid, Role role, SourceTag tag) {
    const double length = piece.shape == Shape::Arc
                              ? (piece.start - piece.centre).norm() * piece.sweep_rad
                              : (piece.end - piece.start).norm();
    if (length <= kSamePointMm && std::abs(piece.end_h - piece.start_h) <= kSamePointMm) return;
    if (piece.shape == Shape::Line) piece.start = tool_;
    // A helix trimmed at an inside corner starts at the height the previous move
    // reached there, not at its own interpolated height: no vertical step.
    piece.start_h = tool_h_;
    piece.rapid = rapid;
    piece.role = role;
    piece.tag = tag;
    if (pending_ && config_.gouge_check_moves > 0 &&
        (role == Role::Contour || role == Role::Corner))
        check_gouge(piece, pending_->move.radius_mm);
    out_.emplace_back(piece);
    tool_ = piece.end;
    tool_h_ = piece.end_h;
}

}  // namespace interp::cutter
