#include "interp/crc_stage.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace interp {

namespace {

// Released commands kept so that an error can still name them (a gouge names a contour move up to
// Config::gouge_check_moves back; blocks may hold several commands each).
constexpr std::size_t kKeepReleased = 256;

int plane_code(Plane p) {
    return p == Plane::XY ? 17 : p == Plane::ZX ? 18 : 19;
}

const AxisVec* move_end(const Canon& c) {
    if (const auto* t = std::get_if<canon::Traverse>(&c.cmd)) return &t->end_mm;
    if (const auto* f = std::get_if<canon::FeedLine>(&c.cmd)) return &f->end_mm;
    if (const auto* a = std::get_if<canon::Arc>(&c.cmd)) return &a->end_mm;
    return nullptr;
}

}  // namespace

const Canon* CrcStage::held(cutter::SourceTag tag) const {
    if (tag < held_base_ || tag >= held_base_ + static_cast<cutter::SourceTag>(held_.size()))
        return nullptr;
    return &held_[static_cast<std::size_t>(tag - held_base_)];
}

void CrcStage::stage(const std::vector<Canon>& cmds, const CrcBlockState& s,
                     const AxisVec& machine_before) {
    staged_ = Staged{};
    staged_.machine_before = machine_before;
    if (!comp_ && s.side == cutter::Side::Off) {
        staged_.direct = &cmds;
        return;
    }
    staged_.fresh = !comp_;
    staged_.plane = staged_.fresh ? s.plane : plane_;
    if (!staged_.fresh && s.plane != plane_)
        fail_plane_change(s, cmds.empty() ? SourceLoc{} : cmds.front().loc);
    // Assigning into the spare compensator of the last block reuses its storage.
    std::swap(staged_.comp, spare_);
    if (staged_.fresh) {
        const PlaneAxes pa = plane_axes(s.plane);
        staged_.comp.emplace(cfg_,
                             cutter::Vec2(machine_before[pa.first], machine_before[pa.second]),
                             machine_before[pa.normal]);
    } else if (staged_.comp) {
        *staged_.comp = *comp_;
    } else {
        staged_.comp.emplace(*comp_);
    }
    cutter::Compensator& comp = *staged_.comp;
    const std::size_t held_before = held_.size();
    const cutter::SourceTag next_before = next_tag_;
    try {
        AxisVec at = machine_before;
        for (const Canon& c : cmds) {
            const cutter::SourceTag tag = next_tag_++;
            held_.push_back(c);
            if (const AxisVec* end = move_end(c)) {
                push_move(comp, c, s, at, tag);
                at = *end;
            } else {
                comp.push(cutter::Marker{tag});
                if (std::holds_alternative<canon::ProgramEnd>(c.cmd)) comp.finish();
            }
        }
        if (!comp.active() && s.side == cutter::Side::Off) {
            comp.finish();
            staged_.disengage = true;
        }
        staged_.outputs = comp.drain();
    } catch (const cutter::CompError& e) {
        const SourceLoc fallback = cmds.empty() ? SourceLoc{} : cmds.front().loc;
        try {
            fail(e, fallback);
        } catch (...) {
            held_.resize(held_before);
            next_tag_ = next_before;
            std::swap(staged_.comp, spare_);
            throw;
        }
    }
}

void CrcStage::emit_staged() {
    if (staged_.direct) {
        for (const Canon& c : *staged_.direct) sink_.emit(c);
        staged_.direct = nullptr;
        return;
    }
    if (!staged_.comp) return;
    if (staged_.fresh) last_end_ = staged_.machine_before;
    plane_ = staged_.plane;
    std::swap(comp_, staged_.comp);
    std::swap(spare_, staged_.comp);  // the previous block's compensator, kept for its storage
    release(staged_.outputs);
    if (staged_.disengage) {
        comp_.reset();
        held_.clear();
        held_base_ = next_tag_;
    }
}

// An arc of several turns (canon::Arc::turns) becomes one Move per turn, each a full circle
// back to the start but the last, with the height shared out by angle: each turn is offset on
// its own, so the tool follows every turn of a helix.
void CrcStage::push_move(cutter::Compensator& comp, const Canon& c, const CrcBlockState& s,
                         const AxisVec& start, cutter::SourceTag tag) const {
    const PlaneAxes pa = plane_axes(plane_);
    cutter::Move m;
    m.side = s.side;
    m.radius_mm = s.radius_mm;
    m.plane = plane_code(s.plane);
    m.tag = tag;
    const auto* a = std::get_if<canon::Arc>(&c.cmd);
    if (!a) {
        const AxisVec& end = *move_end(c);
        m.rapid = std::holds_alternative<canon::Traverse>(c.cmd);
        m.end = {end[pa.first], end[pa.second]};
        m.end_h = end[pa.normal];
        comp.push(m);
        return;
    }
    if (a->plane != plane_) m.plane = plane_code(a->plane);  // the core refuses the change
    m.shape = cutter::Shape::Arc;
    m.centre = {a->centre_mm[pa.first], a->centre_mm[pa.second]};
    m.ccw = a->turns > 0;
    const cutter::Vec2 from(start[pa.first], start[pa.second]);
    const cutter::Vec2 to(a->end_mm[pa.first], a->end_mm[pa.second]);
    const double h0 = start[pa.normal];
    const double h1 = a->end_mm[pa.normal];
    const int extra_turns = std::abs(a->turns) - 1;
    if (extra_turns > 0) {
        constexpr double kTwoPi = 2.0 * std::numbers::pi;
        const cutter::Vec2 r0 = from - m.centre, r1 = to - m.centre;
        double last_sweep = std::atan2(r0.x() * r1.y() - r0.y() * r1.x(), r0.dot(r1));
        if (!m.ccw) last_sweep = -last_sweep;
        if (last_sweep <= 1e-12) last_sweep += kTwoPi;  // end == start: the last turn is whole
        const double total = last_sweep + kTwoPi * extra_turns;
        for (int turn = 1; turn <= extra_turns; ++turn) {
            m.end = from;
            m.end_h = h0 + (h1 - h0) * (kTwoPi * turn / total);
            comp.push(m);
        }
    }
    m.end = to;
    m.end_h = h1;
    comp.push(m);
}

// Turns released compensator output back into canonical commands.
void CrcStage::release(const std::vector<cutter::Output>& outputs) {
    const PlaneAxes pa = plane_axes(plane_);
    cutter::SourceTag last = held_base_;
    for (const cutter::Output& o : outputs) {
        if (const auto* w = std::get_if<cutter::OutWarning>(&o)) {
            const Canon* h = held(w->tag);
            const SourceLoc loc = h ? h->loc : SourceLoc{};
            sink_.emit(Canon{loc, canon::Warning{w->text}});
            continue;
        }
        if (const auto* mk = std::get_if<cutter::OutMarker>(&o)) {
            sink_.emit(*held(mk->tag));
            last = std::max(last, mk->tag);
            continue;
        }
        const auto& mv = std::get<cutter::OutMove>(o);
        const Canon& orig = *held(mv.tag);
        last = std::max(last, mv.tag);
        canon::MoveFlags flags;
        AxisVec end = last_end_;
        if (const auto* t = std::get_if<canon::Traverse>(&orig.cmd)) {
            flags = t->flags;
            end = t->end_mm;
        } else if (const auto* f = std::get_if<canon::FeedLine>(&orig.cmd)) {
            flags = f->flags;
            end = f->end_mm;
        } else if (const auto* a = std::get_if<canon::Arc>(&orig.cmd)) {
            flags = a->flags;
            end = a->end_mm;
        }
        // Corner pieces are inserted before their block's move: the rotary axes wait for it.
        if (mv.role == cutter::Role::Corner) end = last_end_;
        end[pa.first] = mv.end.x();
        end[pa.second] = mv.end.y();
        end[pa.normal] = mv.end_h;
        if (mv.shape == cutter::Shape::Line) {
            if (mv.rapid)
                sink_.emit(Canon{orig.loc, canon::Traverse{end, flags}});
            else
                sink_.emit(Canon{orig.loc, canon::FeedLine{end, flags}});
        } else {
            canon::Arc a;
            a.plane = plane_;
            a.end_mm = end;
            a.centre_mm[pa.first] = mv.centre.x();
            a.centre_mm[pa.second] = mv.centre.y();
            a.centre_mm[pa.normal] = mv.start_h;
            a.turns = mv.ccw ? 1 : -1;
            a.flags = flags;
            sink_.emit(Canon{orig.loc, a});
        }
        last_end_ = end;
    }
    // Output comes in tag order, so older commands are no longer released; a few are kept for
    // error messages.
    const cutter::SourceTag keep_from =
        last - std::min<cutter::SourceTag>(last - held_base_, kKeepReleased);
    while (held_base_ < keep_from) {
        held_.pop_front();
        ++held_base_;
    }
}

// Tags are sequence numbers of commands; the message names their source lines instead.
void CrcStage::fail(const cutter::CompError& e, const SourceLoc& fallback) const {
    const Canon* at = held(e.at_block);
    const SourceLoc loc = at ? at->loc : fallback;
    const std::string text = e.message([&](cutter::SourceTag tag) {
        const Canon* h = held(tag);
        if (!h) return std::string("an earlier block");
        if (h->loc.file != loc.file) return fmt::format("line {} of {}", h->loc.line, h->loc.file);
        return fmt::format("line {}", h->loc.line);
    });
    throw Error(loc, text);
}

void CrcStage::fail_plane_change(const CrcBlockState& s, const SourceLoc& loc) const {
    const std::optional<cutter::SourceTag> held_tag = comp_->held_move();
    const cutter::CompError e(fmt::format("cutter comp: the plane changed from G{} to G{} while "
                                          "compensation is active; cancel it with G40 first",
                                          plane_code(plane_), plane_code(s.plane)),
                              held_tag.value_or(next_tag_), next_tag_);
    fail(e, loc);
}

}  // namespace interp
