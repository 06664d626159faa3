// Native text form of the canonical commands (see canon.hpp for the contract).
#include "interp/canon.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string_view>

namespace interp {

namespace {

constexpr std::array<char, kMachineAxes> kAxisLetters{'X', 'Y', 'Z', 'A', 'B', 'C'};

std::string_view plane_name(Plane p) {
    switch (p) {
        case Plane::ZX:
            return "ZX";
        case Plane::YZ:
            return "YZ";
        default:
            return "XY";
    }
}

// XYZ always; rotary axes only when they are away from zero, so 3-axis output stays short while
// still being a pure function of the value.
std::string axes_text(const AxisVec& v) {
    std::string s = fmt::format("X{} Y{} Z{}", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]));
    for (int i = 3; i < kMachineAxes; ++i)
        if (fmt_num(v[i]) != "0") s += fmt::format(" {}{}", kAxisLetters[i], fmt_num(v[i]));
    return s;
}

std::string flags_text(const canon::MoveFlags& f) {
    std::string s;
    if (f.force_full_override) s += " override=100%";
    if (f.force_programmed_feed) s += " programmed-feed";
    if (f.rotary_shortest_path) s += " rotary-shortest";
    if (f.rotary_degrees) s += " rotary-degrees";
    if (f.exact_stop) s += " exact-stop";
    return s;
}

std::string quoted(const std::string& t) {
    std::string s = "\"";
    for (char c : t) {
        if (c == '"' || c == '\\') s += '\\';
        s += c;
    }
    return s + "\"";
}

struct TextVisitor {
    std::string operator()(const canon::Traverse& c) const {
        return "traverse " + axes_text(c.end_mm) + flags_text(c.flags);
    }
    std::string operator()(const canon::FeedLine& c) const {
        return "feed " + axes_text(c.end_mm) + flags_text(c.flags);
    }
    std::string operator()(const canon::Arc& c) const {
        return fmt::format("arc {} turns={} {} centre=({} {} {}){}", plane_name(c.plane), c.turns,
                           axes_text(c.end_mm), fmt_num(c.centre_mm[0]), fmt_num(c.centre_mm[1]),
                           fmt_num(c.centre_mm[2]), flags_text(c.flags));
    }
    std::string operator()(const canon::SetFeedRate& c) const {
        return fmt::format("feed-rate {}mm/s", fmt_num(c.feed_mm_s));
    }
    std::string operator()(const canon::SetRapidRate& c) const {
        return fmt::format("rapid-rate {}mm/s", fmt_num(c.rapid_mm_s));
    }
    std::string operator()(const canon::SetBlending& c) const {
        if (c.exact) return "blending exact";
        if (c.tolerance_mm <= 0) return "blending continuous tolerance=default";
        return fmt::format("blending continuous tolerance={}mm", fmt_num(c.tolerance_mm));
    }
    std::string operator()(const canon::SetFeedMode& c) const {
        return c.per_minute ? "feed-mode per-minute" : "feed-mode inverse-time";
    }
    std::string operator()(const canon::Dwell& c) const {
        return fmt::format("dwell {}s", fmt_num(c.seconds));
    }
    std::string operator()(const canon::SetSpindleSpeed& c) const {
        return fmt::format("spindle-speed {}rpm", fmt_num(c.rpm));
    }
    std::string operator()(const canon::Spindle& c) const {
        switch (c.dir) {
            case SpindleDir::Cw:
                return "spindle cw";
            case SpindleDir::Ccw:
                return "spindle ccw";
            default:
                return "spindle stop";
        }
    }
    std::string operator()(const canon::SpindleOrient& c) const {
        return fmt::format("spindle-orient tip={}deg", fmt_num(c.tip_angle_deg));
    }
    std::string operator()(const canon::Coolant& c) const {
        return c.flood ? "coolant on" : "coolant off";
    }
    std::string operator()(const canon::SpindleClamp& c) const {
        return c.clamp ? "spindle-clamp on" : "spindle-clamp off";
    }
    std::string operator()(const canon::ToolChange& c) const {
        return fmt::format("tool-change T{}", c.tool);
    }
    std::string operator()(const canon::SetToolNumber& c) const {
        return fmt::format("tool-number T{}", c.tool);
    }
    std::string operator()(const canon::ToolOffset& c) const {
        return fmt::format("tool-offset X{} Y{} Z{}", fmt_num(c.offset_mm[0]),
                           fmt_num(c.offset_mm[1]), fmt_num(c.offset_mm[2]));
    }
    std::string operator()(const canon::Offsets& c) const {
        return fmt::format("offsets G{} origin=({}) shift=({})", 53 + c.wcs, axes_text(c.wcs_mm),
                           axes_text(c.shift_mm));
    }
    std::string operator()(const canon::SelectPlane& c) const {
        return fmt::format("plane {}", plane_name(c.plane));
    }
    std::string operator()(const canon::Units& c) const {
        return c.inch ? "units inch" : "units mm";
    }
    std::string operator()(const canon::SetOutput& c) const {
        return fmt::format("set-output {}{} {}", c.plc_address ? "PLC" : "H", c.port,
                           c.level ? 1 : 0);
    }
    std::string operator()(const canon::WaitInput& c) const {
        return fmt::format("wait-input PLC{} level={} timeout={}s", c.port, c.level ? 1 : 0,
                           fmt_num(c.timeout_s));
    }
    std::string operator()(const canon::Sync&) const { return "sync"; }
    std::string operator()(const canon::ConditionalMove& c) const {
        std::string s = "conditional-move";
        for (const auto& a : c.axes) {
            if (!a) continue;
            s += fmt::format(" {}:speed={}mm/s,input={},level={}", kAxisLetters[a->axis],
                             fmt_num(a->speed_mm_s), a->port, a->level ? 1 : 0);
            if (a->max_travel_mm) s += ",max=" + fmt_num(*a->max_travel_mm);
        }
        return s + flags_text(c.flags);
    }
    std::string operator()(const canon::LatchConfig& c) const {
        return fmt::format("latch-config {} input={} level={}", kAxisLetters[c.axis], c.port,
                           c.level ? 1 : 0);
    }
    std::string operator()(const canon::LatchClear&) const { return "latch-clear"; }
    std::string operator()(const canon::LatchStopDistance& c) const {
        return fmt::format("latch-stop-distance {}", kAxisLetters[c.axis]);
    }
    std::string operator()(const canon::Message& c) const { return "message " + quoted(c.text); }
    std::string operator()(const canon::IntMessage& c) const {
        return fmt::format("int-message {}", c.code);
    }
    std::string operator()(const canon::HomeDone& c) const {
        return fmt::format("home-done {} at={}", kAxisLetters[c.axis], fmt_num(c.position_mm));
    }
    std::string operator()(const canon::Stop& c) const {
        return c.optional ? "optional-stop" : "stop";
    }
    std::string operator()(const canon::Warning& c) const { return "warning " + quoted(c.text); }
    std::string operator()(const canon::ProgramEnd& c) const {
        return c.rewind ? "program-end rewind" : "program-end";
    }
};

}  // namespace

std::string fmt_num(double v) {
    if (std::abs(v) < 0.00005) return "0";  // never print "-0"
    std::string s = fmt::format("{:.4f}", v);
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
    return s;
}

std::string to_text(const CanonCommand& c) {
    return std::visit(TextVisitor{}, c);
}

std::string to_text(const Canon& c) {
    return fmt::format("{} {}", c.loc.line, to_text(c.cmd));
}

std::string untripped_message(const canon::ConditionalMove& cm, const AxisVec& stop_mm) {
    std::string text = "G904:";
    const char* sep = " ";
    for (const auto& w : cm.axes) {
        if (!w) continue;
        text +=
            fmt::format("{}{} stopped at {} mm with input {} not at level {}", sep, "XYZ"[w->axis],
                        fmt_num(stop_mm[w->axis]), w -> port, w -> level ? 1 : 0);
        sep = "; ";
    }
    return text + " (the maximum travel or a soft limit came first)";
}

}  // namespace interp
