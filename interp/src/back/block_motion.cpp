// The motion steps of a block: G00 (with NcStudio's Z split), G01, G02/G03, canned cycles and hole
// patterns through the cycles core, and the stops and program end.
#include <cmath>
#include <numbers>

#include "block_run.hpp"
#include "interp/arc.hpp"
#include "interp/hole_patterns.hpp"

namespace interp::back {

// ---------------------------------------------------------------------------------------------
// Motion.

AxisVec BlockRun::programmed_target() const {
    AxisVec t = st.pos.prog_mm;
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a)) t[a] = st.motion.incremental ? t[a] + axis_value(a) : axis_value(a);
    return t;
}

// NcStudio G00 (G00-2): when Z rises, Z moves first; when it falls, the other axes move first.
void BlockRun::emit_rapid(const AxisVec& end) {
    if (cfg_.use_default_speed) select_rapid();
    const AxisVec& start = st.pos.machine_mm;
    constexpr double eps = 1e-9;
    const double dz = end[2] - start[2];
    bool others = false;
    for (int a = 0; a < kMachineAxes; ++a)
        if (a != 2 && std::abs(end[a] - start[a]) > eps) others = true;
    if (cfg_.g00_z_split && std::abs(dz) > eps && others) {
        AxisVec mid = dz > 0 ? start : end;
        mid[2] = dz > 0 ? end[2] : start[2];
        emit(canon::Traverse{mid, flags_});
    }
    emit(canon::Traverse{end, flags_});
    st.pos.machine_mm = end;
}

// G00-4: with "use default speed" on, a move runs at the machine's default feed / rapid speed,
// in a G905 block at the programmed ones; the stream announces a rate when it changes.
void BlockRun::select_feed(const char* what) {
    double f = cfg_.default_feed_mm_s;
    if (flags_.force_programmed_feed) {
        if (!st.feed.programmed.feed_set || st.feed.programmed.feed_mm_s <= 0)
            fail(loc_g(gcode(905)), fmt::format("G905: no feed rate programmed (F) for {}", what));
        f = st.feed.programmed.feed_mm_s;
    } else if (f <= 0) {
        fail(b_.loc,
             fmt::format("no default feed configured for {} (use default speed is on)", what));
    }
    if (st.feed.feed_set && st.feed.feed_mm_s == f) return;
    st.feed.feed_mm_s = f;
    st.feed.feed_set = true;
    emit(canon::SetFeedRate{f});
}

void BlockRun::select_rapid() {
    const double r = flags_.force_programmed_feed ? st.feed.programmed.rapid_mm_s : 0.0;
    if (st.feed.rapid_mm_s == r) return;
    st.feed.rapid_mm_s = r;
    emit(canon::SetRapidRate{r});
}

void BlockRun::require_feed(const char* what) {
    if (cfg_.use_default_speed) return select_feed(what);
    if (st.feed.feed_set && st.feed.feed_mm_s > 0) return;
    if (!st.feed.feed_set && cfg_.default_feed_mm_s > 0) {
        st.feed.feed_mm_s = cfg_.default_feed_mm_s;
        st.feed.feed_set = true;
        emit(canon::SetFeedRate{st.feed.feed_mm_s});
        return;
    }
    fail(b_.loc, fmt::format("no feed rate programmed (F) for {}", what));
}

void BlockRun::move_line(bool rapid, bool machine_coords) {
    AxisVec end;
    AxisVec prog_end{};  // the programmed end point (not under G53)
    if (machine_coords) {
        end = st.pos.machine_mm;
        for (int a = 0; a < kMachineAxes; ++a)
            if (has_axis(a))  // MCS-3 REC: tool length compensation stays active under G53
                end[a] = axis_value(a) + (a < 3 ? st.tool.offset_mm[a] : 0.0);
    } else {
        prog_end = programmed_target();
        end = to_machine(prog_end);
    }
    if (rapid) {
        emit_rapid(end);
    } else {
        require_feed("a feed move");
        emit(canon::FeedLine{end, flags_});
        st.pos.machine_mm = end;
    }
    if (machine_coords)
        resync_prog();
    else
        st.pos.prog_mm = prog_end;
}

void BlockRun::move_arc(bool ccw) {
    require_feed("an arc");
    const PlaneAxes pa = plane_axes(st.motion.plane);
    // The arc starts where the machine is, seen in the current program frame.
    const AxisVec offset = offset_total();
    const AxisVec start = prog_of_machine(st.pos.machine_mm, offset);
    AxisVec end = st.pos.prog_mm;
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a)) end[a] = st.motion.incremental ? start[a] + axis_value(a) : axis_value(a);

    ArcInput in;
    in.start = {start[pa.first], start[pa.second]};
    in.end = {end[pa.first], end[pa.second]};
    in.ccw = ccw;
    in.tolerance_mm = cfg_.arc_tolerance_mm;
    in.v54_small_radius_is_half_circle = cfg_.v54_compat;
    const char cf = kCentreLetter[pa.first];
    const char cs = kCentreLetter[pa.second];
    const bool has_r = b_.has('R');
    const bool has_ijk = b_.has(cf) || b_.has(cs);
    if (has_r && has_ijk) fail(b_.loc_of('R'), "arc has both R and I/J/K");
    if (has_r) {
        in.radius = b_.get('R') * st.units.mm_per_unit;
    } else if (has_ijk) {
        const double ci = b_.has(cf) ? b_.get(cf) * st.units.mm_per_unit : 0.0;
        const double cj = b_.has(cs) ? b_.get(cs) * st.units.mm_per_unit : 0.0;
        if (cfg_.ijk_incremental)
            in.centre = Eigen::Vector2d(in.start.x() + ci, in.start.y() + cj);
        else
            in.centre = Eigen::Vector2d(ci, cj);
    }
    // ARC-9 (V5.4): K is the lead of a multi-turn helix in G17 when it is not a centre word.
    const bool k_lead = cfg_.v54_compat && st.motion.plane == Plane::XY && b_.has('K') && has_r;
    in.want_sweep = k_lead;
    ArcResult r;
    if (std::string why = solve_arc(in, r); !why.empty()) fail(b_.loc, why);

    int extra_turns = 0;
    if (k_lead) {
        const double lead = std::abs(b_.get('K') * st.units.mm_per_unit);
        const double dz = std::abs(end[2] - start[2]);
        if (lead > 0)
            extra_turns = std::max(
                0, static_cast<int>(std::lround(dz / lead - r.sweep_rad / (2 * std::numbers::pi))));
    }

    // Into machine coordinates: the plane must stay a machine plane and circles stay circles.
    // Without programmed transforms (most arcs) both hold trivially.
    Plane mp = st.motion.plane;
    bool flipped = false;
    if (!xf().identity()) {
        const Eigen::Matrix3d L = xf().matrix().linear();
        const Eigen::Vector3d n = L.col(pa.normal);
        int target_normal = -1;
        for (int k = 0; k < 3; ++k) {
            const double rest = n.norm() - std::abs(n[k]);
            if (std::abs(rest) < 1e-9 * n.norm()) target_normal = k;
        }
        if (target_normal < 0)
            fail(b_.loc, "arc plane is not a machine plane after the programmed rotation");
        mp = target_normal == 2 ? Plane::XY : target_normal == 1 ? Plane::ZX : Plane::YZ;
        const PlaneAxes mt = plane_axes(mp);
        Eigen::Matrix2d B;
        B << L(mt.first, pa.first), L(mt.first, pa.second), L(mt.second, pa.first),
            L(mt.second, pa.second);
        const Eigen::Matrix2d BtB = B.transpose() * B;
        const double s2 = 0.5 * BtB.trace();
        if (std::abs(BtB(0, 1)) > 1e-9 * s2 || std::abs(BtB(0, 0) - BtB(1, 1)) > 1e-9 * s2)
            fail(b_.loc, "non-uniform scaling of arc (different G51 factors on the plane axes)");
        flipped = B.determinant() < 0;  // a mirror turns G02 into G03 (ARC-14)
    }
    const PlaneAxes ma = plane_axes(mp);

    AxisVec centre_prog = start;
    centre_prog[pa.first] = r.centre.x();
    centre_prog[pa.second] = r.centre.y();
    const AxisVec centre_m = to_machine(centre_prog, offset);
    const AxisVec end_m = to_machine(end, offset);

    canon::Arc& arc = emit_arc();
    arc.plane = mp;
    arc.end_mm = end_m;
    arc.centre_mm = {centre_m[0], centre_m[1], centre_m[2]};
    arc.centre_mm[ma.normal] = st.pos.machine_mm[ma.normal];
    const bool machine_ccw = ccw != flipped;
    arc.turns = (1 + extra_turns) * (machine_ccw ? 1 : -1);
    arc.flags = flags_;
    st.pos.machine_mm = end_m;
    st.pos.prog_mm = end;
}

void BlockRun::step_motion() {
    if (axis_user_ && axis_user_->code >= gcode(34) && axis_user_->code <= gcode(37))
        return run_hole_pattern();
    if (axis_user_) {
        // G92, G28, G51 … consumed the axis words; a motion code only sets the mode.
        if (motion_code_) {
            st.cycle.cancel();
            st.motion.motion = static_cast<Motion>(*motion_code_ / 10);
        }
        return;
    }
    if (motion_code_) st.cycle.cancel();  // G00-8, G01-5: a group-01 code ends the cycle
    if (!motion_code_ && (st.cycle.active() || (cycle_code_ && *cycle_code_ != gcode(80))))
        return run_cycle();
    if (motion_code_) st.motion.motion = static_cast<Motion>(*motion_code_ / 10);
    const bool arc_mode = st.motion.motion == Motion::ArcCw || st.motion.motion == Motion::ArcCcw;
    // ARC-4: an arc block with I/J/K and no end point is a full circle (S4 `G03 I-20 J0`).
    const bool centre_only =
        arc_mode && motion_code_ && (b_.has('I') || b_.has('J') || b_.has('K'));
    const bool g53 = g(gcode(53));
    if (!any_axis_word() && !centre_only) {
        if (g53) fail(loc_g(gcode(53)), "G53 needs axis words");
        return;
    }
    if (g53) {
        require_no_scaling(gcode(53));
        if (st.motion.incremental) fail(loc_g(gcode(53)), "G53 needs absolute coordinates (G90)");
        if (arc_mode) fail(loc_g(gcode(53)), "G53 works only with G00 or G01");
    }
    switch (st.motion.motion) {
        case Motion::Rapid:
            move_line(true, g53);
            break;
        case Motion::Linear:
            move_line(false, g53);
            break;
        case Motion::ArcCw:
            move_arc(false);
            break;
        case Motion::ArcCcw:
            move_arc(true);
            break;
    }
}

// ---------------------------------------------------------------------------------------------
// Canned cycles (G73–G89) and hole patterns (G34–G37): the cycles core expands a block into simple
// steps in program coordinates; they are transformed and emitted here like any other move.

void BlockRun::step_cycle_modes() {
    if (!group(GGroup::Cycle) && !group(GGroup::CycleReturn)) return;
    if (g(gcode(98))) st.cycle_return_to_r = false;
    if (g(gcode(99))) st.cycle_return_to_r = true;
    if (g(gcode(80))) st.cycle.cancel();
}

cycles::BlockContext BlockRun::cycle_context() const {
    cycles::BlockContext c;
    c.incremental = st.motion.incremental;
    c.return_to_r = st.cycle_return_to_r;
    c.position_mm = {st.pos.prog_mm[0], st.pos.prog_mm[1], st.pos.prog_mm[2]};
    c.feed_mm_min = st.feed.feed_mm_s * 60.0;
    c.spindle_rpm = st.spindle.rpm;
    c.spindle = st.spindle.dir == SpindleDir::Cw    ? cycles::Spindle::Cw
                : st.spindle.dir == SpindleDir::Ccw ? cycles::Spindle::Ccw
                                                    : cycles::Spindle::Stopped;
    c.plane = st.motion.plane == Plane::ZX   ? cycles::Plane::ZX
              : st.motion.plane == Plane::YZ ? cycles::Plane::YZ
                                             : cycles::Plane::XY;
    c.drill_axis_scaled = std::abs(xf().matrix().linear().col(2).norm() - 1.0) > 1e-12;
    return c;
}

cycles::CycleWords BlockRun::cycle_words() const {
    cycles::CycleWords w;
    for (int a = 0; a < 3; ++a)
        if (has_axis(a)) w.axis_mm[a] = axis_value(a);
    if (b_.has('R')) w.r_mm = mm('R');
    if (b_.has('Q')) w.q_mm = mm('Q');
    if (b_.has('P')) w.p_ms = std::round(b_.get('P'));  // LEX-51
    // C-14: NcStudio documents K and uses L in its examples; both are the repeat count.
    if (b_.has('K'))
        w.k = b_.get('K');
    else if (b_.has('L'))
        w.k = b_.get('L');
    if (cfg_.v54_compat) {  // V5.4 G76 X Y Z R U V P F L (G76-4)
        if (b_.has('U')) w.u_mm = mm('U');
        if (b_.has('V')) w.v_mm = mm('V');
    }
    return w;
}

// A machine setting readable as a named parameter: the persisted value (settings file, program
// writes) first, then the machine configuration.
std::optional<double> BlockRun::machine_setting(std::string_view name) const {
    if (auto it = settings().params.find(name); it != settings().params.end()) return it->second;
    if (auto it = cfg_.machine_settings.find(name); it != cfg_.machine_settings.end())
        return it->second;
    return std::nullopt;
}

// The cycle parameters of the machine, with the named-parameter settings (persisted or
// configured) FIXEDCYCLE_BACK (δ of G73/G83, mm) and FIXEDCYCLE_OSS (G76/G87 shift direction)
// taking precedence, so a public.dat or settings-file change reaches the built-in cycles too.
cycles::CycleConfig BlockRun::cycle_config() const {
    cycles::CycleConfig c = cfg_.cycles;
    auto setting = [&](std::string_view name) { return machine_setting(name); };
    if (auto back = setting("FIXEDCYCLE_BACK")) c.retract_mm = *back;
    if (auto oss = setting("FIXEDCYCLE_OSS")) c.oss_direction = static_cast<int>(*oss);
    c.g76_shift_uv = cfg_.v54_compat;
    c.g86_restart_at_r = cfg_.v54_compat;
    if (auto cycp = setting("CYCP")) c.g76_shift_feed_mm_min = *cycp;
    return c;
}

void BlockRun::run_cycle() {
    if (!st.feed.feed_set || cfg_.use_default_speed) require_feed("a canned cycle");
    // LEX-51: the dwell P is whole milliseconds, as for G04 (cycle_words rounds it).
    if (const double p = b_.has('P') ? b_.get('P') : 0; p != std::round(p))
        emit(
            canon::Warning{fmt::format("canned-cycle P{} is not whole milliseconds; rounded to P{}",
                                       fmt_num(p), fmt_num(std::round(p)))});
    std::optional<cycles::CycleCode> code;
    if (cycle_code_ && *cycle_code_ != gcode(80))
        code = cycles::cycle_code_from_g(*cycle_code_ / 10);
    try {
        begin_holes(st.cycle.start_block(code, cycle_words(), cycle_context(), cycle_config()));
    } catch (const cycles::CycleError& e) {
        fail(cycle_code_ ? loc_g(*cycle_code_) : b_.loc, e.what());
    }
}

void BlockRun::run_hole_pattern() {
    const int code = axis_user_->code;
    cycles::PatternWords w;
    if (has_axis(0)) w.x_mm = axis_value(0);
    if (has_axis(1)) w.y_mm = axis_value(1);
    // I is a length for every pattern; J is an angle except in G37, where it is the row pitch.
    if (b_.has('I')) w.i = mm('I');
    if (b_.has('J')) w.j = code == gcode(37) ? mm('J') : b_.get('J');
    if (b_.has('P')) w.p = b_.get('P');
    if (b_.has('K')) w.k = b_.get('K');
    if (cfg_.use_default_speed && st.cycle.active()) require_feed("a hole pattern");
    try {
        cycles::HolePattern holes =
            cycles::hole_pattern_lazy(code / 10, w, st.motion.incremental,
                                      {st.pos.prog_mm[0], st.pos.prog_mm[1]}, st.cycle.active());
        begin_holes(st.cycle.drill_pattern(holes.count, std::move(holes.at), cycle_context(),
                                           cycle_config()));
    } catch (const cycles::CycleError& e) {
        fail(loc_g(code), e.what());
    }
}

// The block's first hole is converted now, inside the block (its errors were all thrown by the
// cycles core already); the executor asks for the others after the commit (next_pending_hole),
// so a K1000000 block never holds more than one hole. A block that also stops or ends the
// program keeps every hole before that stop.
void BlockRun::begin_holes(cycles::BlockHoles&& b) {
    for (const std::string& w : b.warnings) emit(canon::Warning{w});
    holes_.emplace(std::move(b.holes));
    cycle_dir_at_start_ = st.spindle.dir;
    next_pending_hole();
    if (m(0) || m(1) || m(2) || m(30))
        while (next_pending_hole()) {
        }
}

bool BlockRun::next_pending_hole() {
    if (!holes_ || !holes_->next(hole_steps_)) return false;
    emit_cycle_steps(hole_steps_);
    return true;
}

// The cutter-tip direction of an oriented stop as a machine XY angle: rotation and mirroring
// turn the direction the OSS table gives in program coordinates.
double BlockRun::orient_angle_deg(const cycles::Vec3& tip_dir) const {
    const Eigen::Vector3d m =
        xf().matrix().linear() * Eigen::Vector3d(tip_dir[0], tip_dir[1], tip_dir[2]);
    double deg = std::atan2(m.y(), m.x()) * 180.0 / std::numbers::pi;
    if (deg < 0) deg += 360.0;
    deg = std::round(deg * 1e9) / 1e9;  // 179.99999999997 after a G68 R90 pair prints as 180
    return deg >= 360.0 ? 0.0 : deg + 0.0;
}

void BlockRun::emit_cycle_steps(const std::vector<cycles::Step>& steps) {
    const SpindleDir dir_at_start = cycle_dir_at_start_;
    const double modal_feed = st.feed.feed_mm_s;
    double announced_feed = modal_feed;
    auto set_dir = [&](SpindleDir d) {
        st.spindle.dir = d;
        emit(canon::Spindle{d});
    };
    for (const cycles::Step& step : steps) {
        std::visit(
            [&](const auto& s) {
                using T = std::decay_t<decltype(s)>;
                if constexpr (std::is_same_v<T, cycles::Rapid> || std::is_same_v<T, cycles::Feed>) {
                    AxisVec p = st.pos.prog_mm;
                    for (int a = 0; a < 3; ++a) p[a] = s.to_mm[a];
                    const AxisVec m = to_machine(p);
                    if constexpr (std::is_same_v<T, cycles::Rapid>) {
                        emit_rapid(m);
                    } else {
                        const double f = s.feed_mm_min / 60.0;
                        if (f != announced_feed) {
                            emit(canon::SetFeedRate{f});
                            announced_feed = f;
                        }
                        canon::MoveFlags fl = flags_;
                        if (s.override_locked) fl.force_full_override = true;
                        emit(canon::FeedLine{m, fl});
                        st.pos.machine_mm = m;
                    }
                    st.pos.prog_mm = p;
                } else if constexpr (std::is_same_v<T, cycles::Dwell>) {
                    emit(canon::Dwell{s.seconds});
                } else if constexpr (std::is_same_v<T, cycles::SpindleStop>) {
                    set_dir(SpindleDir::Stop);
                } else if constexpr (std::is_same_v<T, cycles::SpindleOrient>) {
                    st.spindle.dir = SpindleDir::Stop;
                    emit(canon::SpindleOrient{orient_angle_deg(s.tip_dir)});
                } else if constexpr (std::is_same_v<T, cycles::SpindleReverse>) {
                    set_dir(st.spindle.dir == SpindleDir::Cw ? SpindleDir::Ccw : SpindleDir::Cw);
                } else if constexpr (std::is_same_v<T, cycles::SpindleRestart>) {
                    set_dir(dir_at_start);
                } else if constexpr (std::is_same_v<T, cycles::SpindleCw>) {
                    set_dir(SpindleDir::Cw);
                } else if constexpr (std::is_same_v<T, cycles::SpindleSpeed>) {
                    st.spindle.rpm = s.rpm;
                    emit(canon::SetSpindleSpeed{s.rpm});
                } else if constexpr (std::is_same_v<T, cycles::OperatorRetract>) {
                    // G88 manual retract: the program pauses, the operator jogs out and resumes.
                    emit(canon::Stop{false});
                }
            },
            step);
    }
    if (announced_feed != modal_feed) emit(canon::SetFeedRate{modal_feed});
}

// ---------------------------------------------------------------------------------------------
// Stops and the end of the program (M30-1, SCL-9, ROT-4, MIR-7, G992-1, TLC-6).

void BlockRun::program_end(bool rewind) {
    xf_mut().clear();
    st.cycle.cancel();
    st.cycle_return_to_r = false;
    st.crc_side = cutter::Side::Off;
    st.feed_clamp_warned = false;
    st.coord.g992_mm = {};
    st.coord.g992_active = false;
    st.motion = MotionModal{};
    st.units = UnitsModal{};
    st.moved = false;
    if (!(st.path == PathModal{})) {
        st.path = PathModal{};
        emit(canon::SetBlending{false, 0});
    }
    // G00-3 REC: the programmed rapid speed ends with the program. Under G00-4 the announced one
    // is the machine's own and stays in step with the stream.
    if (cfg_.use_default_speed)
        st.feed.programmed.rapid_mm_s = 0;
    else
        st.feed.rapid_mm_s = 0;
    st.tool.length_mode = ToolLengthMode::Off;
    st.tool.h_register.reset();
    const std::array<double, 3> before = st.tool.offset_mm;
    st.tool.offset_mm = {};
    if (before != st.tool.offset_mm) emit(canon::ToolOffset{st.tool.offset_mm});
    // AUTOSTOPSPINDLE (S0 §4.1.2 #13) as a machine setting overrides the configured default.
    const std::optional<double> autostop = machine_setting("AUTOSTOPSPINDLE");
    if (autostop ? *autostop != 0 : cfg_.end_stops_spindle) {
        if (st.spindle.dir != SpindleDir::Stop) emit(canon::Spindle{SpindleDir::Stop});
        if (st.coolant.flood) emit(canon::Coolant{false});
        st.spindle.dir = SpindleDir::Stop;
        st.coolant.flood = false;
    }
    // M30-1, END-1: with ENABLE_CTP on, a normal end goes to the fixed point CTP_POS (machine
    // coordinates, S0 §4.1.2 #19–22) as a G00 would, Z first when it rises; the spindle is
    // already stopped when AUTOSTOPSPINDLE asks for it.
    if (machine_setting("ENABLE_CTP").value_or(0) != 0) {
        static constexpr std::string_view kCtp[3] = {"CTP_POS.X", "CTP_POS.Y", "CTP_POS.Z"};
        AxisVec ctp = st.pos.machine_mm;
        for (int a = 0; a < 3; ++a)
            if (auto v = machine_setting(kCtp[a])) ctp[a] = *v;
        emit_rapid(ctp);
    }
    announce_offsets();
    resync_prog();
    emit(canon::ProgramEnd{rewind});
    st.started = false;
}

void BlockRun::step_stop() {
    if (b_.m.empty()) return;
    if (m(0)) emit(canon::Stop{false});
    if (m(1) && cfg_.optional_stop) emit(canon::Stop{true});
    if (m(2)) program_end(false);
    if (m(30)) program_end(true);
}

}  // namespace interp::back
