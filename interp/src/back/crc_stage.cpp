#include "interp/crc_stage.hpp"

#include <fmt/format.h>

#include <regex>

namespace interp {

namespace {

int plane_code(Plane p) {
    return p == Plane::XY ? 17 : p == Plane::ZX ? 18 : 19;
}

}  // namespace

void CrcStage::pass(const std::vector<Canon>& cmds, const CrcBlockState& s,
                    const AxisVec& machine_before) {
    if (!comp_) {
        if (s.side == cutter::Side::Off) {
            for (const Canon& c : cmds) sink_.emit(c);
            return;
        }
        plane_ = s.plane;
        const PlaneAxes pa = plane_axes(plane_);
        comp_.emplace(cfg_, cutter::Vec2(machine_before[pa.first], machine_before[pa.second]),
                      machine_before[pa.normal]);
        last_end_ = machine_before;
    }
    try {
        for (const Canon& c : cmds) {
            const cutter::SourceTag tag = next_tag_++;
            held_.emplace(tag, Held{c});
            if (std::holds_alternative<canon::Traverse>(c.cmd) ||
                std::holds_alternative<canon::FeedLine>(c.cmd) ||
                std::holds_alternative<canon::Arc>(c.cmd)) {
                push_move(c, s, tag);
            } else {
                comp_->push(cutter::Marker{tag});
                if (std::holds_alternative<canon::ProgramEnd>(c.cmd)) comp_->finish();
            }
        }
    } catch (const cutter::CompError& e) {
        fail(e);
    }
    release();
    if (!comp_->active() && s.side == cutter::Side::Off) {
        comp_->finish();
        release();
        comp_.reset();
        held_.clear();
    }
}

void CrcStage::push_move(const Canon& c, const CrcBlockState& s, cutter::SourceTag tag) {
    const PlaneAxes pa = plane_axes(plane_);
    cutter::Move m;
    m.side = s.side;
    m.radius_mm = s.radius_mm;
    m.plane = plane_code(s.plane);
    m.tag = tag;
    if (const auto* a = std::get_if<canon::Arc>(&c.cmd)) {
        if (a->plane != plane_) m.plane = plane_code(a->plane);  // the core refuses the change
        if (a->turns > 1 || a->turns < -1)
            throw cutter::CompError("cutter comp: a multi-turn helix cannot be compensated", tag,
                                    tag);
        m.shape = cutter::Shape::Arc;
        m.end = {a->end_mm[pa.first], a->end_mm[pa.second]};
        m.centre = {a->centre_mm[pa.first], a->centre_mm[pa.second]};
        m.ccw = a->turns > 0;
        m.end_h = a->end_mm[pa.normal];
    } else {
        const AxisVec& end = std::holds_alternative<canon::Traverse>(c.cmd)
                                 ? std::get<canon::Traverse>(c.cmd).end_mm
                                 : std::get<canon::FeedLine>(c.cmd).end_mm;
        m.rapid = std::holds_alternative<canon::Traverse>(c.cmd);
        m.end = {end[pa.first], end[pa.second]};
        m.end_h = end[pa.normal];
    }
    comp_->push(m);
}

// Turns released compensator output back into canonical commands.
void CrcStage::release() {
    const PlaneAxes pa = plane_axes(plane_);
    cutter::SourceTag last = 0;
    for (const cutter::Output& o : comp_->drain()) {
        if (const auto* w = std::get_if<cutter::OutWarning>(&o)) {
            auto it = held_.find(w->tag);
            const SourceLoc loc = it != held_.end() ? it->second.canon.loc : SourceLoc{};
            sink_.emit(Canon{loc, canon::Warning{with_lines(w->text)}});
            continue;
        }
        if (const auto* mk = std::get_if<cutter::OutMarker>(&o)) {
            const Canon& c = held_.at(mk->tag).canon;
            sink_.emit(c);
            last = std::max(last, mk->tag);
            continue;
        }
        const auto& mv = std::get<cutter::OutMove>(o);
        const Canon& orig = held_.at(mv.tag).canon;
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
    // Output comes in tag order, so older commands can no longer be referenced.
    held_.erase(held_.begin(), held_.lower_bound(last));
}

// The core names blocks by their tags ("between line 4 and line 5"); tags here are sequence
// numbers of commands, so they are translated back to source lines.
std::string CrcStage::with_lines(const std::string& text) const {
    static const std::regex kTag("line ([0-9]+)");
    std::string out;
    auto begin = std::sregex_iterator(text.begin(), text.end(), kTag);
    std::size_t pos = 0;
    for (auto it = begin; it != std::sregex_iterator(); ++it) {
        out.append(text, pos, static_cast<std::size_t>(it->position()) - pos);
        const auto h = held_.find(std::stoll((*it)[1].str()));
        out += h != held_.end() ? fmt::format("line {}", h->second.canon.loc.line) : it->str();
        pos = static_cast<std::size_t>(it->position() + it->length());
    }
    out.append(text, pos);
    return out;
}

void CrcStage::fail(const cutter::CompError& e) const {
    auto it = held_.find(e.second_block);
    const SourceLoc loc = it != held_.end() ? it->second.canon.loc : SourceLoc{};
    throw Error(loc, with_lines(e.what()));
}

}  // namespace interp
