#include "interp/canon_print.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace interp {

// ---------------------------------------------------------------------------------------------

void NativePrinter::emit(const Canon& c) {
    if (main_file_.empty()) main_file_ = std::string(c.loc.file);
    // Lines of the main program print as "12"; others (public.dat, …) as "public.dat:12".
    const std::string s = c.loc.file == main_file_
                              ? to_text(c)
                              : fmt::format("{}:{} {}", c.loc.file, c.loc.line, to_text(c.cmd));
    std::fputs(s.c_str(), out_);
    std::fputc('\n', out_);
}

// ---------------------------------------------------------------------------------------------

namespace {

std::string f4(double v) {
    if (std::abs(v) < 0.00005) v = 0;  // rs274 never prints -0.0000
    return fmt::format("{:.4f}", v);
}

const char* lcnc_plane(Plane p) {
    switch (p) {
        case Plane::ZX:
            return "CANON_PLANE_XZ";
        case Plane::YZ:
            return "CANON_PLANE_YZ";
        default:
            return "CANON_PLANE_XY";
    }
}

template <typename T>
bool is(const CanonCommand& c) {
    return std::holds_alternative<T>(c);
}

bool is_move(const CanonCommand& c) {
    return is<canon::Traverse>(c) || is<canon::FeedLine>(c) || is<canon::Arc>(c);
}

}  // namespace

void LinuxCncPrinter::line(const std::string& call) {
    fmt::print(out_, "{:5d} N..... {}\n", ++n_, call);
}

void LinuxCncPrinter::preamble() {
    started_ = true;
    line("USE_LENGTH_UNITS(CANON_UNITS_MM)");
    line(fmt::format("SET_G5X_OFFSET({}, {})", offsets_.wcs, axes(offsets_.wcs_mm)));
    line(fmt::format("SET_G92_OFFSET({})", axes(offsets_.shift_mm)));
    line("SET_XY_ROTATION(0.0000)");
    line("SET_FEED_REFERENCE(CANON_XYZ)");
    line("ON_RESET()");
}

// Offsets are in program units except rotary axes (degrees).
std::string LinuxCncPrinter::axes(const AxisVec& v) const {
    return fmt::format("{}, {}, {}, {}, {}, {}", f4(unit(v[0])), f4(unit(v[1])), f4(unit(v[2])),
                       f4(v[3]), f4(v[4]), f4(v[5]));
}

void LinuxCncPrinter::emit(const Canon& c) {
    if (c.loc.line != block_line_) flush_block();
    block_line_ = c.loc.line;
    block_.push_back(c.cmd);
}

// A block is printed whole so that the program-end block can be replaced by LinuxCNC's own
// end-of-program sequence (which resets more than the NcStudio end does).
void LinuxCncPrinter::flush_block() {
    if (block_.empty()) return;
    const bool ends = std::any_of(block_.begin(), block_.end(),
                                  [](const CanonCommand& c) { return is<canon::ProgramEnd>(c); });
    std::size_t last_move = 0;
    for (std::size_t i = 0; i < block_.size(); ++i)
        if (is_move(block_[i])) last_move = i + 1;
    for (std::size_t i = 0; i < block_.size(); ++i) {
        const CanonCommand& c = block_[i];
        if (ends && i >= last_move &&
            (is<canon::Spindle>(c) || is<canon::Coolant>(c) || is<canon::Offsets>(c) ||
             is<canon::ToolOffset>(c) || is<canon::SetBlending>(c))) {
            if (is<canon::Offsets>(c)) offsets_ = std::get<canon::Offsets>(c);
            continue;
        }
        print(c);
    }
    block_.clear();
}

void LinuxCncPrinter::print(const CanonCommand& cmd) {
    if (const auto* o = std::get_if<canon::Offsets>(&cmd)) {
        const bool first = !started_;
        const canon::Offsets before = offsets_;
        offsets_ = *o;
        if (first) return preamble();
        if (o->wcs != before.wcs || o->wcs_mm != before.wcs_mm) {
            line(fmt::format("SET_G5X_OFFSET({}, {})", o->wcs, axes(o->wcs_mm)));
            line(fmt::format("SET_G92_OFFSET({})", axes(o->shift_mm)));
            line("SET_XY_ROTATION(0.0000)");
        } else if (o->shift_mm != before.shift_mm) {
            line(fmt::format("SET_G92_OFFSET({})", axes(o->shift_mm)));
        }
        return;
    }
    if (!started_) preamble();
    auto work = [&](const AxisVec& m) {
        AxisVec w{};
        for (int a = 0; a < kMachineAxes; ++a) {
            w[a] = m[a] - offsets_.wcs_mm[a] - offsets_.shift_mm[a] - (a < 3 ? tool_mm_[a] : 0);
            if (a < 3) w[a] = unit(w[a]);
        }
        return w;
    };
    auto move_args = [&](const AxisVec& m) {
        const AxisVec w = work(m);
        return fmt::format("{}, {}, {}, {}, {}, {}", f4(w[0]), f4(w[1]), f4(w[2]), f4(w[3]),
                           f4(w[4]), f4(w[5]));
    };
    std::visit(
        [&](const auto& c) {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, canon::Traverse>) {
                line("STRAIGHT_TRAVERSE(" + move_args(c.end_mm) + ")");
                exact_stop_note(c.flags);
            } else if constexpr (std::is_same_v<T, canon::FeedLine>) {
                line("STRAIGHT_FEED(" + move_args(c.end_mm) + ")");
                exact_stop_note(c.flags);
            } else if constexpr (std::is_same_v<T, canon::Warning>) {
                // Not a call: rs274 prints nothing; `cnc` reports warnings on stderr.
            } else if constexpr (std::is_same_v<T, canon::SetBlending>) {
                // rs274 prints the tolerance in program units; P0 and no P both print 0.
                if (c.exact) {
                    line("SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)");
                } else {
                    const double tol = c.tolerance_mm > 0 ? unit(c.tolerance_mm) : 0.0;
                    line(fmt::format("SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, {:.6f})", tol));
                    line(fmt::format("SET_NAIVECAM_TOLERANCE({})", f4(tol)));
                }
            } else if constexpr (std::is_same_v<T, canon::Arc>) {
                const PlaneAxes pa = plane_axes(c.plane);
                const AxisVec e = work(c.end_mm);
                AxisVec cm = c.end_mm;
                for (int a = 0; a < 3; ++a) cm[a] = c.centre_mm[a];
                const AxisVec cw = work(cm);
                line(fmt::format("ARC_FEED({}, {}, {}, {}, {}, {}, {}, {}, {})", f4(e[pa.first]),
                                 f4(e[pa.second]), f4(cw[pa.first]), f4(cw[pa.second]), c.turns,
                                 f4(e[pa.normal]), f4(e[3]), f4(e[4]), f4(e[5])));
                exact_stop_note(c.flags);
            } else if constexpr (std::is_same_v<T, canon::SetFeedRate>) {
                line(fmt::format("SET_FEED_RATE({})", f4(unit(c.feed_mm_s * 60))));
            } else if constexpr (std::is_same_v<T, canon::Dwell>) {
                line(fmt::format("DWELL({})", f4(c.seconds)));
            } else if constexpr (std::is_same_v<T, canon::SetSpindleSpeed>) {
                line(fmt::format("SET_SPINDLE_SPEED(0, {})", f4(c.rpm)));
            } else if constexpr (std::is_same_v<T, canon::Spindle>) {
                line(c.dir == SpindleDir::Cw    ? "START_SPINDLE_CLOCKWISE(0)"
                     : c.dir == SpindleDir::Ccw ? "START_SPINDLE_COUNTERCLOCKWISE(0)"
                                                : "STOP_SPINDLE_TURNING(0)");
            } else if constexpr (std::is_same_v<T, canon::Coolant>) {
                flood_ = c.flood;
                if (c.flood) {
                    line("FLOOD_ON()");
                } else {
                    line("MIST_OFF()");
                    line("FLOOD_OFF()");
                }
            } else if constexpr (std::is_same_v<T, canon::ToolChange>) {
                line(fmt::format("SELECT_TOOL({})", c.tool));
                line("START_CHANGE()");
                line("STOP_SPINDLE_TURNING(0)");
                line(fmt::format("CHANGE_TOOL({})", c.tool));
            } else if constexpr (std::is_same_v<T, canon::ToolOffset>) {
                tool_mm_ = c.offset_mm;
                line(fmt::format(
                    "USE_TOOL_LENGTH_OFFSET({} {} {}, 0.0000 0.0000 0.0000, "
                    "0.0000 0.0000 0.0000)",
                    f4(unit(c.offset_mm[0])), f4(unit(c.offset_mm[1])), f4(unit(c.offset_mm[2]))));
            } else if constexpr (std::is_same_v<T, canon::SelectPlane>) {
                line(fmt::format("SELECT_PLANE({})", lcnc_plane(c.plane)));
            } else if constexpr (std::is_same_v<T, canon::Units>) {
                mm_per_unit_ = c.inch ? 25.4 : 1.0;
                line(c.inch ? "USE_LENGTH_UNITS(CANON_UNITS_INCHES)"
                            : "USE_LENGTH_UNITS(CANON_UNITS_MM)");
            } else if constexpr (std::is_same_v<T, canon::SetFeedMode>) {
                line(fmt::format("SET_FEED_MODE(0, {})", c.per_minute ? 0 : 1));
            } else if constexpr (std::is_same_v<T, canon::ProgramEnd>) {
                line(fmt::format("SET_G5X_OFFSET(1, {})", axes(offsets_.wcs_mm)));
                line("SET_XY_ROTATION(0.0000)");
                line("SET_FEED_MODE(0, 0)");
                line("SET_FEED_RATE(0.0000)");
                line("STOP_SPINDLE_TURNING(0)");
                line("SET_SPINDLE_MODE(0 0.0000)");
                if (flood_) line("FLOOD_OFF()");
                flood_ = false;
                mm_per_unit_ = 1.0;
                tool_mm_ = {};
                if (c.rewind) line("PALLET_SHUTTLE()");
                line("PROGRAM_END()");
            } else {
                std::string t = to_text(CanonCommand(c));
                std::replace(t.begin(), t.end(), '"', '\'');
                line("COMMENT(\"native: " + t + "\")");
            }
        },
        cmd);
}

// LinuxCNC has no G09; the stop is kept visible rather than dropped.
void LinuxCncPrinter::exact_stop_note(const canon::MoveFlags& f) {
    if (f.exact_stop) line("COMMENT(\"native: exact-stop\")");
}

void LinuxCncPrinter::finish() {
    flush_block();
    if (!started_) preamble();
    line("ON_RESET()");
    line("ON_RESET()");
}

// ---------------------------------------------------------------------------------------------

void WarningPrinter::emit(const Canon& c) {
    if (const auto* w = std::get_if<canon::Warning>(&c.cmd)) warning(c.loc, w->text);
}

void WarningPrinter::warning(const SourceLoc& loc, const std::string& text) {
    ++count_;
    fmt::print(out_, "{}:{}:{}: warning: {}\n", loc.file, loc.line, loc.col, text);
}

// ---------------------------------------------------------------------------------------------

// Inline and by value: the points are built in registers, and an array built field by field and
// read back whole stalled on store forwarding (a tenth of an arc line's time).
inline void SummarySink::extend(double x, double y, double z) {
    if (moves_ == 0) {
        min_ = max_ = {x, y, z};
        return;
    }
    min_[0] = std::min(min_[0], x);
    max_[0] = std::max(max_[0], x);
    min_[1] = std::min(min_[1], y);
    max_[1] = std::max(max_[1], y);
    min_[2] = std::min(min_[2], z);
    max_[2] = std::max(max_[2], z);
}

void SummarySink::line_to(const AxisVec& end, bool rapid) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) d2 += (end[a] - pos_[a]) * (end[a] - pos_[a]);
    const double len = std::sqrt(d2);
    if (rapid) {
        rapid_len_ += len;
    } else {
        feed_len_ += len;
        if (feed_mm_s_ > 0) feed_time_ += len / feed_mm_s_;
    }
    extend(pos_[0], pos_[1], pos_[2]);
    ++moves_;
    extend(end[0], end[1], end[2]);
    pos_ = end;
}

namespace {

// A stand-in for the angle of (x, y) that grows with it through [0, 4) and is exactly 0, 1, 2, 3
// at +x, +y, -x, -y, so "is this quadrant point inside the sweep" needs no trigonometry.
double pseudo_angle(double x, double y) {
    const double s = std::abs(x) + std::abs(y);
    if (s == 0) return 0;
    const double t = x / s;
    return y >= 0 ? 1 - t : 3 + t;
}

}  // namespace

// Extents include the arc's quadrant points inside its sweep; the length is the helix length.
// One atan2 per arc (the sweep, for the length): the extents only compare pseudo-angles, and a
// quadrant point's Z may be taken as the start's because the start and end already bound Z.
void SummarySink::arc(const canon::Arc& a) {
    const PlaneAxes pa = plane_axes(a.plane);
    const double sx = pos_[pa.first] - a.centre_mm[pa.first];
    const double sy = pos_[pa.second] - a.centre_mm[pa.second];
    const double ex = a.end_mm[pa.first] - a.centre_mm[pa.first];
    const double ey = a.end_mm[pa.second] - a.centre_mm[pa.second];
    const double r = std::hypot(sx, sy);
    const double two_pi = 2 * std::numbers::pi;
    // Counter-clockwise angle from start to end in (-pi, pi], turned to the arc's direction.
    double d = std::atan2(sx * ey - sy * ex, sx * ex + sy * ey);
    if (a.turns < 0) d = -d;
    while (d <= 1e-12) d += two_pi;
    const double sweep = d + two_pi * (std::abs(a.turns) - 1);
    extend(pos_[0], pos_[1], pos_[2]);
    ++moves_;
    static constexpr double kCos[4] = {1, 0, -1, 0};
    static constexpr double kSin[4] = {0, 1, 0, -1};
    const bool full = sweep >= two_pi - 1e-12;
    const double ps = pseudo_angle(sx, sy);
    // Position of a pseudo-angle along the arc from its start, in [0, 4).
    const auto along = [&](double p) {
        double v = a.turns > 0 ? p - ps : ps - p;
        return v < 0 ? v + 4 : v;
    };
    const double end_at = along(pseudo_angle(ex, ey));
    // A point given as (first, second, normal) of the plane, passed on as (x, y, z) without going
    // through memory (a point array indexed by axis stalled on store forwarding).
    const auto extend_in_plane = [&](double u, double v, double w) {
        switch (a.plane) {
            case Plane::ZX:
                return extend(v, w, u);
            case Plane::YZ:
                return extend(w, u, v);
            default:
                return extend(u, v, w);
        }
    };
    for (int k = 0; k < 4; ++k) {
        if (!full && along(k) > end_at) continue;
        extend_in_plane(a.centre_mm[pa.first] + r * kCos[k], a.centre_mm[pa.second] + r * kSin[k],
                        pos_[pa.normal]);
    }
    extend(a.end_mm[0], a.end_mm[1], a.end_mm[2]);
    // A plane arc (most arcs) skips hypot: hypot(x, ±0) is |x| exactly (C Annex F).
    const double dn = a.end_mm[pa.normal] - pos_[pa.normal];
    const double len = dn == 0 ? std::abs(r * sweep) : std::hypot(r * sweep, dn);
    feed_len_ += len;
    if (feed_mm_s_ > 0) feed_time_ += len / feed_mm_s_;
    pos_ = a.end_mm;
}

void SummarySink::emit(const Canon& c) {
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, canon::Traverse>)
                line_to(v.end_mm, true);
            else if constexpr (std::is_same_v<T, canon::FeedLine>)
                line_to(v.end_mm, false);
            else if constexpr (std::is_same_v<T, canon::Arc>)
                arc(v);
            else if constexpr (std::is_same_v<T, canon::SetFeedRate>)
                feed_mm_s_ = v.feed_mm_s;
            else if constexpr (std::is_same_v<T, canon::Dwell>)
                feed_time_ += v.seconds;
            else if constexpr (std::is_same_v<T, canon::ToolChange>)
                tools_.insert(v.tool);
            else if constexpr (std::is_same_v<T, canon::SetToolNumber>)
                tools_.insert(v.tool);
            else if constexpr (std::is_same_v<T, canon::HomeDone>)
                pos_[v.axis] = v.position_mm;
        },
        c.cmd);
}

}  // namespace interp
