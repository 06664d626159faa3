// Per-cycle step generators: one small function per cycle, chosen by a table.
// Each function follows the numbered "加工过程说明" list of its cycle in the
// NcStudio manual (S0 §3.6.4); G76/G87/G88, unsupported there, follow the same
// lists plus the FEATURES.md recommendations (G76-1, G87-1, G88-1).

#include "hole_steps.hpp"

#include <fmt/format.h>

#include <cmath>

namespace interp::cycles::detail {
namespace {

constexpr double kSameLevelMm = 1e-9;
constexpr long kMaxPecks = 100000;

/// Appends moves, dropping the zero-length ones (a hole straight below the tool,
/// a G99 retract that is already at R), and tracks the tool position.
class Emitter {
  public:
    Emitter(const HoleSpec& hole, Vec3& position, std::vector<Step>& out)
        : hole_(hole), pos_(position), out_(out) {}

    void rapid_to_level(double c_mm) { move_level(c_mm, true); }
    void feed_to_level(double c_mm) { move_level(c_mm, false); }
    /// A tapping move: the feed must stay locked to the spindle.
    void tap_to_level(double c_mm) {
        lock_override_ = true;
        move_level(c_mm, false);
        lock_override_ = false;
    }

    /// Moves in the positioning plane at the current drilling-axis level.
    void rapid_in_plane(double a_mm, double b_mm) {
        Vec3 to = pos_;
        to[hole_.axes.a] = a_mm;
        to[hole_.axes.b] = b_mm;
        move(to, true);
    }
    void feed_in_plane(double a_mm, double b_mm, double feed_mm_min) {
        Vec3 to = pos_;
        to[hole_.axes.a] = a_mm;
        to[hole_.axes.b] = b_mm;
        bool same = true;
        for (int i = 0; i < 3; ++i) same = same && std::abs(to[i] - pos_[i]) <= kSameLevelMm;
        if (same) return;
        out_.emplace_back(Feed{to, feed_mm_min, false});
        pos_ = to;
    }
    void rapid_shift(double sign) {
        rapid_in_plane(hole_.pos_a_mm + sign * hole_.q_mm * hole_.shift_dir[0],
                       hole_.pos_b_mm + sign * hole_.q_mm * hole_.shift_dir[1]);
    }
    void dwell() {
        if (hole_.dwell_s > 0.0) out_.emplace_back(Dwell{hole_.dwell_s});
    }
    void push(Step step) { out_.push_back(step); }
    /// Oriented stop before a shift of shift_sign·Q: the tip points the other way, so the
    /// shift takes it off the bore wall (G76 shifts +Q, G87 −Q: its tip faces the OSS side).
    void orient(double shift_sign) {
        Vec3 tip{};
        // + 0.0 turns −0 into 0 for the printed form.
        tip[hole_.axes.a] = -shift_sign * hole_.shift_dir[0] + 0.0;
        tip[hole_.axes.b] = -shift_sign * hole_.shift_dir[1] + 0.0;
        push(SpindleOrient{tip});
    }
    double level() const { return pos_[hole_.axes.c]; }

  private:
    void move_level(double c_mm, bool rapid) {
        Vec3 to = pos_;
        to[hole_.axes.c] = c_mm;
        move(to, rapid);
    }
    void move(const Vec3& to, bool rapid) {
        bool same = true;
        for (int i = 0; i < 3; ++i) same = same && std::abs(to[i] - pos_[i]) <= kSameLevelMm;
        if (same) return;
        if (rapid)
            out_.emplace_back(Rapid{to});
        else
            out_.emplace_back(Feed{to, hole_.feed_mm_min, lock_override_});
        pos_ = to;
    }

    const HoleSpec& hole_;
    Vec3& pos_;
    std::vector<Step>& out_;
    bool lock_override_ = false;
};

// G98 never returns below R: a cycle started with the tool under the R plane
// would otherwise move between holes below R.
double return_level(const HoleSpec& h) {
    return h.return_to_r ? h.r_mm : std::max(h.initial_mm, h.r_mm);
}

/// Steps 1–2 of every cycle but G87: position in the plane, rapid to R.
void approach(const HoleSpec& h, Emitter& e) {
    e.rapid_in_plane(h.pos_a_mm, h.pos_b_mm);
    e.rapid_to_level(h.r_mm);
}

long peck_count(const HoleSpec& h) {
    const double pecks = std::ceil((h.r_mm - h.z_mm) / h.q_mm);
    if (pecks > kMaxPecks)
        throw CycleError(fmt::format("G{}: Q{:g} gives more than {} pecks for the depth {:g}",
                                     g_number(h.code), h.q_mm, kMaxPecks, h.r_mm - h.z_mm));
    return static_cast<long>(pecks);
}

// G81: 1) G00 to X Y 2) G00 to R 3) G01 to Z 4) G00 to initial (G98) or R (G99).
void g81(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.rapid_to_level(return_level(h));
}

// G82: as G81 with 4) dwell P before the rapid retract.
void g82(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.dwell();
    e.rapid_to_level(return_level(h));
}

// G73: 3) feed Q below the depth reached so far 4) rapid up δ 5) repeat to Z
// 6) rapid to initial/R. No δ retract after the last peck (it is the retract).
void g73(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    approach(h, e);
    double depth = h.r_mm;
    while (depth > h.z_mm) {
        depth = std::max(depth - h.q_mm, h.z_mm);
        e.feed_to_level(depth);
        // A δ larger than the depth cut so far would lift above R: stop at R.
        if (depth > h.z_mm) e.rapid_to_level(std::min(depth + cfg.retract_mm, h.r_mm));
    }
    e.rapid_to_level(return_level(h));
}

// G83: 3) feed Q 4) rapid to R 5) rapid down to δ above the previous depth
// 6) feed Q deeper 7) rapid to R 8) repeat to Z 9) rapid to initial/R.
void g83(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    approach(h, e);
    double depth = h.r_mm;
    while (depth > h.z_mm) {
        if (depth < h.r_mm) e.rapid_to_level(std::min(depth + cfg.retract_mm, h.r_mm));
        depth = std::max(depth - h.q_mm, h.z_mm);
        e.feed_to_level(depth);
        if (depth > h.z_mm) e.rapid_to_level(h.r_mm);
    }
    e.rapid_to_level(return_level(h));
}

// G74/G84: 3) G01 to Z 4) dwell P, reverse 5) G01 up to R 6) dwell P, reverse
// back 7) G00 to the initial level (G98). The tapping speed parameter replaces S
// for the cut (NcStudio G84 note) and S is restored once back at R.
void tap(const HoleSpec& h, const CycleConfig& cfg, Emitter& e) {
    approach(h, e);
    if (cfg.tap_spindle_rpm) e.push(SpindleSpeed{*cfg.tap_spindle_rpm});
    e.tap_to_level(h.z_mm);
    e.dwell();
    e.push(SpindleReverse{});
    e.tap_to_level(h.r_mm);
    e.dwell();
    e.push(SpindleReverse{});
    if (cfg.tap_spindle_rpm) e.push(SpindleSpeed{h.spindle_rpm});
    e.rapid_to_level(return_level(h));
}
void g74(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    tap(h, cfg, e);
}
void g84(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    tap(h, cfg, e);
}

// Tapping needs the spindle already turning the cycle's way (G74 M04, G84 M03).
void check_tap_spindle(const HoleSpec& h, const BlockContext& ctx) {
    const bool left = h.code == CycleCode::G74;
    if (!left && h.code != CycleCode::G84) return;
    const Spindle required = left ? Spindle::Ccw : Spindle::Cw;
    if (ctx.spindle != required)
        throw CycleError(fmt::format("G{} needs the spindle running {} ({}) before the cycle",
                                     g_number(h.code), left ? "counter-clockwise" : "clockwise",
                                     left ? "M04" : "M03"));
}

// G76: 2) G00 to R without orienting 3) G01 to Z, dwell P, oriented stop
// 4) shift Q in the OSS direction 5) G00 to initial/R 6) restart the spindle.
// REC G76-1: shift back before the restart so the next hole starts centred.
// V5.4 (G76-4): the shift is U in X and V in Y, fed at the CYCP speed; the tip points against
// it. Shifting back at the return level follows REC G76-1 as in the 6th edition.
void g76(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.dwell();
    e.orient(+1.0);
    if (h.shift_uv_mm)
        e.feed_in_plane(h.pos_a_mm + (*h.shift_uv_mm)[0], h.pos_b_mm + (*h.shift_uv_mm)[1],
                        h.shift_feed_mm_min);
    else
        e.rapid_shift(+1.0);
    e.rapid_to_level(return_level(h));
    e.rapid_shift(0.0);
    e.push(SpindleRestart{});
}

// G85: 3) G01 to Z 4) G01 back to R 5) G00 to initial (G98).
void g85(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.feed_to_level(h.r_mm);
    e.rapid_to_level(return_level(h));
}

// G86: 3) G01 to Z 4) spindle stop 5) G00 to initial/R 6) spindle restarts.
// V5.4 restarts at R (C-45), then goes on to the initial level under G98.
void g86(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.push(SpindleStop{});
    if (cfg.g86_restart_at_r) {
        e.rapid_to_level(h.r_mm);
        e.push(SpindleRestart{});
        e.rapid_to_level(return_level(h));
        return;
    }
    e.rapid_to_level(return_level(h));
    e.push(SpindleRestart{});
}

// G87 back boring, R is the bottom: 1) G00 to X Y 2) oriented stop, shift −Q
// 3) G00 down to R, shift +Q 4) spindle CW 5) G01 up to Z 6) dwell P, oriented
// stop, shift −Q 7) G00 up to the initial level 8) shift +Q, restart.
void g87(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    e.rapid_in_plane(h.pos_a_mm, h.pos_b_mm);
    e.orient(-1.0);
    e.rapid_shift(-1.0);
    e.rapid_to_level(h.r_mm);
    e.rapid_shift(0.0);
    e.push(SpindleCw{});
    e.feed_to_level(h.z_mm);
    e.dwell();
    e.orient(-1.0);
    e.rapid_shift(-1.0);
    e.rapid_to_level(h.initial_mm);
    e.rapid_shift(0.0);
    e.push(SpindleRestart{});
}

// G88: 3) G01 to Z 4) dwell P, spindle stop 5) G01 to R (feed mode) or the
// operator jogs out (manual mode) 6) G00 to initial/R 7) spindle CW (restart).
void g88(const HoleSpec& h, const CycleConfig& cfg, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.dwell();
    e.push(SpindleStop{});
    if (cfg.g88_retract == G88Retract::Feed)
        e.feed_to_level(h.r_mm);
    else
        e.push(OperatorRetract{});
    e.rapid_to_level(return_level(h));
    e.push(SpindleRestart{});
}

// G89: 3) G01 to Z 4) dwell P 5) G01 up to R 6) G00 to initial/R.
void g89(const HoleSpec& h, const CycleConfig&, const BlockContext&, Emitter& e) {
    approach(h, e);
    e.feed_to_level(h.z_mm);
    e.dwell();
    e.feed_to_level(h.r_mm);
    e.rapid_to_level(return_level(h));
}

using CycleFn = void (*)(const HoleSpec&, const CycleConfig&, const BlockContext&, Emitter&);
struct CycleEntry {
    CycleCode code;
    CycleFn fn;
};
constexpr CycleEntry kCycles[] = {
    {CycleCode::G73, g73}, {CycleCode::G74, g74}, {CycleCode::G76, g76}, {CycleCode::G81, g81},
    {CycleCode::G82, g82}, {CycleCode::G83, g83}, {CycleCode::G84, g84}, {CycleCode::G85, g85},
    {CycleCode::G86, g86}, {CycleCode::G87, g87}, {CycleCode::G88, g88}, {CycleCode::G89, g89},
};

void check_levels(const HoleSpec& h) {
    if (h.code == CycleCode::G87) {
        // R above Z (the manual's own example) only warns: see make_spec.
        if (h.initial_mm < h.z_mm)
            throw CycleError(fmt::format(
                "G87 back boring: the initial level ({:g}) must lie above Z ({:g}), the tool "
                "returns there past the bore",
                h.initial_mm, h.z_mm));
    } else if (h.z_mm > h.r_mm) {
        throw CycleError(fmt::format("G{}: the hole bottom Z ({:g}) lies above the R plane ({:g})",
                                     g_number(h.code), h.z_mm, h.r_mm));
    }
}

}  // namespace

AxisMap axis_map(Plane plane, bool drill_axis_follows_plane) {
    if (!drill_axis_follows_plane) return {0, 1, 2};
    switch (plane) {
        case Plane::XY:
            return {0, 1, 2};
        case Plane::ZX:
            return {2, 0, 1};
        case Plane::YZ:
            return {1, 2, 0};
    }
    return {0, 1, 2};
}

std::array<double, 2> oss_shift(const CycleConfig& cfg) {
    const int d = cfg.oss_direction;
    if (cfg.oss_table == OssTable::NcStudio) {
        switch (d) {
            case 0:
                return {1, 0};
            case 1:
                return {-1, 0};
            case 2:
                return {0, 1};
            case 3:
                return {0, -1};
        }
    } else {
        switch (d) {
            case 1:
                return {1, 0};
            case 0:
            case 2:
                return {-1, 0};
            case 3:
                return {0, 1};
            case 4:
                return {0, -1};
        }
    }
    throw CycleError(
        fmt::format("oriented spindle stop direction #FIXEDCYCLE_OSS={} is not in the table", d));
}

void check_hole(const HoleSpec& hole, const BlockContext& ctx, const CycleConfig&) {
    check_levels(hole);
    if (hole.code == CycleCode::G73 || hole.code == CycleCode::G83) peck_count(hole);
    check_tap_spindle(hole, ctx);
}

void append_hole(const HoleSpec& hole, const BlockContext& ctx, const CycleConfig& cfg,
                 Vec3& position, std::vector<Step>& out) {
    for (const auto& entry : kCycles) {
        if (entry.code != hole.code) continue;
        Emitter emitter(hole, position, out);
        entry.fn(hole, cfg, ctx, emitter);
        return;
    }
    throw CycleError(fmt::format("G{}: no step generator", g_number(hole.code)));
}

}  // namespace interp::cycles::detail
