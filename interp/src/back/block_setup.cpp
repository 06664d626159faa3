// The modal and setting steps of a block: units, feed, spindle, tool, coolant, I/O, dwell, plane,
// cutter and length compensation, work systems, distance mode, programmed transforms, offset
// writes, and the machine-facing extended codes (G28, G904, G906, G916/G918/G919).
#include <cmath>

#include "block_run.hpp"

namespace interp::back {

void BlockRun::step_units() {
    if (!group(GGroup::Units)) return;
    double mpu = st.units.mm_per_unit;
    if (g(gcode(20)) || g(gcode(70))) mpu = 25.4;
    if (g(gcode(21)) || g(gcode(71))) mpu = 1.0;
    // C-37: NcStudio wants the units at the front of the program; later is accepted but odd.
    if (st.moved)
        emit(canon::Warning{"G20/G21 after a move: units belong at the start of the program"});
    st.units.mm_per_unit = mpu;
}

// Announced after the plane, in LinuxCNC's order, though the value applied from the start of the
// block (F and every length of the block are in the new units).
void BlockRun::announce_units() {
    if (group(GGroup::Units)) emit(canon::Units{st.units.inch()});  // G20/G21/G70/G71
}

// F in a block whose motion mode is G00 sets the rapid speed only (G00-3).
void BlockRun::step_feed() {
    if (group(GGroup::FeedMode) && g(gcode(94))) emit(canon::SetFeedMode{true});
    if (!b_.has('F')) return;
    const double f = b_.get('F');
    if (f < 0) fail(b_.loc_of('F'), fmt::format("negative feed rate F{}", fmt_num(f)));
    const double f_mm_s = f * st.units.mm_per_unit / 60.0;
    // A canned-cycle block's F is the drilling feed even though G00 is the modal motion.
    const bool cycle_block =
        (cycle_code_ && *cycle_code_ != gcode(80)) || (st.cycle.active() && !motion_code_);
    const bool rapid_mode = !cycle_block && (motion_code_ ? *motion_code_ == gcode(0)
                                                          : st.motion.motion == Motion::Rapid);
    // G00-4: under "use default speed" F only fills the programmed registers; the rates a move
    // runs at are announced when it is emitted (select_feed, select_rapid).
    const bool announce = !cfg_.use_default_speed;
    FeedRegisters& reg = announce ? st.feed : st.feed.programmed;
    if (rapid_mode && !g(gcode(904))) {
        double r = f_mm_s;
        if (cfg_.max_rapid_mm_s > 0) r = std::min(r, cfg_.max_rapid_mm_s);
        reg.rapid_mm_s = r;
        if (announce) emit(canon::SetRapidRate{r});
        if (reg.feed_set) return;  // G00-3 REC: a first bare F also primes the cutting feed
    }
    double cut_mm_s = f_mm_s;
    if (cfg_.max_feed_mm_s > 0 && cut_mm_s > cfg_.max_feed_mm_s) {
        cut_mm_s = cfg_.max_feed_mm_s;
        if (!st.feed_clamp_warned)
            emit(canon::Warning{fmt::format("F{} exceeds the maximum feed {} mm/min; clamped",
                                            fmt_num(f), fmt_num(cut_mm_s * 60.0))});
        st.feed_clamp_warned = true;
    }
    reg.feed_mm_s = cut_mm_s;
    reg.feed_set = true;
    if (announce) emit(canon::SetFeedRate{cut_mm_s});
}

void BlockRun::step_spindle_speed() {
    if (!b_.has('S')) return;
    const double s = b_.get('S');
    if (s < 0) fail(b_.loc_of('S'), fmt::format("negative spindle speed S{}", fmt_num(s)));
    st.spindle.rpm = s;
    emit(canon::SetSpindleSpeed{s});
}

// T selects a tool; NcStudio 6th edition changes it at once (TSET-4), V5.4 waits for M06.
// M903 only renames the current tool.
void BlockRun::step_tool() {
    std::optional<int> t;
    if (b_.has('T')) t = int_word('T', 0, 99999, "tool number");
    if (m(903)) {
        int n = 0;
        if (t)
            n = *t;
        else if (b_.has('P'))
            n = int_word('P', 0, 99999, "M903");
        else
            fail(loc_m(903), "M903 needs T<tool> (or P<tool>)");
        st.tool.current = n;
        emit(canon::SetToolNumber{n});
        update_tool_offset(loc_m(903));
        return;
    }
    const bool change_now = t && (cfg_.t_changes_tool || m(6));
    if (m(6) && !t && !cfg_.t_changes_tool && st.tool.current == 0)
        fail(loc_m(6), "M06 without a selected tool (T)");
    if (!change_now) {
        if (t) st.tool.current = *t;  // V5.4: selected, changed by a later M06
        if (m(6) && !cfg_.t_changes_tool) emit(canon::ToolChange{st.tool.current});
        return;
    }
    st.tool.current = *t;
    emit(canon::ToolChange{*t});
    update_tool_offset(b_.loc_of('T'));
}

void BlockRun::step_spindle() {
    if (b_.m.empty()) return;
    if (m(3))
        st.spindle.dir = SpindleDir::Cw;
    else if (m(4))
        st.spindle.dir = SpindleDir::Ccw;
    else if (m(5))
        st.spindle.dir = SpindleDir::Stop;
    else
        return;
    emit(canon::Spindle{st.spindle.dir});
}

void BlockRun::step_coolant() {
    if (b_.m.empty()) return;
    if (m(8) || m(9)) {
        st.coolant.flood = m(8);
        emit(canon::Coolant{st.coolant.flood});
    }
    if (m(10) || m(11)) {
        const int code = m(10) ? 10 : 11;
        if (!cfg_.v54_compat) {
            emit(canon::Warning{fmt::format(
                "{} is an invalid instruction in NcStudio 6th edition; ignored", mname(code))});
            return;
        }
        st.coolant.clamped = m(10);
        emit(canon::SpindleClamp{st.coolant.clamped});
    }
}

// M801 messages, M802 integer messages, M901 outputs, M902 homing done (S0 §3.10).
void BlockRun::step_io() {
    if (b_.m.empty()) return;
    if (m(801)) {
        if (!b_.msg) fail(loc_m(801), "M801 needs MSG \"text\"");
        emit(canon::Message{*b_.msg});
    }
    if (m(802)) {
        if (!b_.has('P')) fail(loc_m(802), "M802 needs P<integer message>");
        const double p = b_.get('P');
        if (p != std::floor(p)) fail(b_.loc_of('P'), "M802: P must be an integer");
        emit(canon::IntMessage{static_cast<std::int64_t>(p)});
    }
    if (m(901)) {
        canon::SetOutput o;
        if (b_.kw.plc) {
            if (!b_.kw.level) fail(loc_m(901), "M901 PLC[...] needs LEVEL0 or LEVEL1");
            o.port = *b_.kw.plc;
            o.plc_address = true;
            if (*b_.kw.level != 0 && *b_.kw.level != 1)
                fail(loc_m(901), "M901: LEVEL must be 0 or 1");
            o.level = *b_.kw.level == 1;
        } else if (b_.has('H') && b_.has('P')) {
            o.port = int_word('H', 0, 63, "M901 port");
            o.level = int_word('P', 0, 1, "M901 level") == 1;
        } else {
            fail(loc_m(901), "M901 needs PLC[addr] LEVEL<0|1> or H<port> P<0|1>");
        }
        if (o.port >= 0 && o.port < 64) {
            const std::uint64_t bit = std::uint64_t{1} << o.port;
            st.io.outputs = o.level ? (st.io.outputs | bit) : (st.io.outputs & ~bit);
        }
        emit(o);
    }
    if (m(902)) {
        if (!b_.has('H')) fail(loc_m(902), "M902 needs H<axis> (0=X 1=Y 2=Z 3=A)");
        const int axis = int_word('H', 0, 3, "M902 axis");
        // C-31: 6th edition uses the machine-origin parameter, V5.4 zero.
        const double at = cfg_.v54_compat ? 0.0 : cfg_.home_position_mm[axis];
        st.pos.machine_mm[axis] = at;
        resync_prog();
        emit(canon::HomeDone{axis, at});
    }
}

void BlockRun::step_dwell() {
    if (!group(GGroup::NonModal)) return;
    if (!g(gcode(4))) return;
    double seconds = 0;
    if (b_.has('P')) {
        // DW-1, LEX-51: P is whole milliseconds ("不使用小数点"); `P1000.` and `P=#1` are fine,
        // a real fraction is rounded, as the manual's millisecond timer would.
        const double ms = std::round(b_.get('P'));
        if (ms != b_.get('P'))
            emit(canon::Warning{fmt::format("G04 P{} is not whole milliseconds; rounded to P{}",
                                            fmt_num(b_.get('P')), fmt_num(ms))});
        seconds = ms / 1000.0;
    } else if (b_.has('X') && !any_axis_word()) {
        seconds = b_.get('X');
    } else {
        fail(loc_g(gcode(4)), "G04 needs P<milliseconds>");
    }
    if (seconds < 0) fail(loc_g(gcode(4)), "G04: negative dwell time");
    emit(canon::Dwell{seconds});
}

void BlockRun::step_plane() {
    if (!group(GGroup::Plane)) return;
    Plane p;
    if (g(gcode(17)))
        p = Plane::XY;
    else if (g(gcode(18)))
        p = Plane::ZX;
    else if (g(gcode(19)))
        p = Plane::YZ;
    else
        return;
    st.motion.plane = p;
    emit(canon::SelectPlane{p});
}

void BlockRun::step_tool_length() {
    if (!group(GGroup::ToolLength)) return;
    if (!g(gcode(43)) && !g(gcode(44)) && !g(gcode(49))) return;
    const int code = g(gcode(43)) ? gcode(43) : g(gcode(44)) ? gcode(44) : gcode(49);
    if (code == gcode(49)) {
        st.tool.length_mode = ToolLengthMode::Off;
        st.tool.h_register.reset();
    } else {
        st.tool.length_mode = code == gcode(43) ? ToolLengthMode::Plus : ToolLengthMode::Minus;
        if (b_.has('H'))
            st.tool.h_register = int_word('H', 0, 99999, "tool length register");
        else
            st.tool.h_register.reset();
    }
    const std::array<double, 3> before = st.tool.offset_mm;
    update_tool_offset(b_.has('H') ? b_.loc_of('H') : loc_g(code));
    // Announce even an unchanged offset: the program asked for it (and LinuxCNC prints it).
    if (before == st.tool.offset_mm) emit(canon::ToolOffset{st.tool.offset_mm});
}

// G40/G41/G42 and D (CRC-1, CRC-7, EX-35: D alone only selects the radius).
void BlockRun::step_cutter_comp() {
    if (b_.has('D')) st.crc_d = int_word('D', 0, 99999, "cutter radius register");
    if (group(GGroup::Crc)) {
        if (g(gcode(40))) st.crc_side = cutter::Side::Off;
        if (g(gcode(41))) st.crc_side = cutter::Side::Left;
        if (g(gcode(42))) st.crc_side = cutter::Side::Right;
    }
    if (st.crc_side == cutter::Side::Off) return;
    const int reg = st.crc_d.value_or(st.tool.current);
    double radius = 0;
    if (reg != 0) {
        const ToolEntry* e = settings().tools.find(reg);
        if (!e)
            fail(b_.has('D') ? b_.loc_of('D') : b_.loc,
                 fmt::format("cutter radius compensation: tool {} is not in the tool table", reg));
        radius = e->diameter_mm / 2;
    }
    st.crc.radius_mm = radius;
}

// The side the compensator sees: one mirrored plane axis swaps G41 and G42 (CRC-13, MIR-4).
void BlockRun::step_crc_effective() {
    st.crc.plane = st.motion.plane;
    st.crc.side = st.crc_side;
    if (st.crc_side == cutter::Side::Off || xf().identity()) return;
    const PlaneAxes pa = plane_axes(st.motion.plane);
    const Eigen::Matrix3d L = xf().matrix().linear();
    const double det = L(pa.first, pa.first) * L(pa.second, pa.second) -
                       L(pa.first, pa.second) * L(pa.second, pa.first);
    if (det < 0)
        st.crc.side = st.crc_side == cutter::Side::Left ? cutter::Side::Right : cutter::Side::Left;
}

void BlockRun::step_wcs() {
    if (!group(GGroup::Wcs)) return;
    for (int i = 0; i < kWorkSystems; ++i) {
        if (!g(gcode(54 + i))) continue;
        st.coord.wcs = i;
        announce_offsets();
        resync_prog();
    }
}

// G61 / G64 [P] (PATH-2, PATH-3, PATH-9). Announced every time one is written, as LinuxCNC does,
// so a consumer needs no state to follow it. P belongs to G64 here, so another user of P in the
// same block would make it ambiguous.
void BlockRun::step_path_mode() {
    if (!group(GGroup::PathMode)) return;
    if (g(gcode(61))) {
        st.path = PathModal{true, 0};
        emit(canon::SetBlending{true, 0});
        return;
    }
    double tol_mm = 0;
    if (b_.has('P')) {
        static constexpr int kOtherPUsers[] = {gcode(4),   gcode(51),  gcode(922), gcode(923),
                                               gcode(906), gcode(34),  gcode(35),  gcode(36),
                                               gcode(37)};
        const bool cycle_block = (cycle_code_ && *cycle_code_ != gcode(80)) ||
                                 (st.cycle.active() && !motion_code_ && any_axis_word());
        if (cycle_block)
            fail(b_.loc_of('P'), "G64 in a canned-cycle block: P is ambiguous");
        for (int other : kOtherPUsers)
            if (g(other))
                fail(b_.loc_of('P'), fmt::format("G64 and {} in one block: P is ambiguous",
                                                 gname(other)));
        for (int other : {802, 901, 903})
            if (m(other))
                fail(b_.loc_of('P'), fmt::format("G64 and {} in one block: P is ambiguous",
                                                 mname(other)));
        tol_mm = mm('P');
        if (tol_mm < 0)
            fail(b_.loc_of('P'),
                 fmt::format("G64: negative blend tolerance P{}", fmt_num(b_.get('P'))));
    }
    st.path = PathModal{false, tol_mm};
    emit(canon::SetBlending{false, tol_mm});
}

void BlockRun::step_distance() {
    if (!group(GGroup::Distance)) return;
    if (g(gcode(90))) st.motion.incremental = false;
    if (g(gcode(91))) st.motion.incremental = true;
}

void BlockRun::require_no_mirror_coord_change() const {
    if (!cfg_.mirror_forbids_coord_changes || !xf().mirror_active()) return;
    static constexpr int kCoordCodes[] = {gcode(28), gcode(53),  gcode(54),  gcode(55),
                                          gcode(56), gcode(57),  gcode(58),  gcode(59),
                                          gcode(92), gcode(921), gcode(922), gcode(992)};
    for (int code : kCoordCodes)
        if (g(code))
            fail(loc_g(code),
                 fmt::format("{} is not allowed while mirroring (G51.1) is active", gname(code)));
}

void BlockRun::require_no_scaling(int code) const {
    if (xf().scaling_active())
        fail(loc_g(code),
             fmt::format("{} is not allowed while scaling (G51) is active", gname(code)));
}

// G50/G51 scaling, G50.1/G51.1 mirroring, G68/G69 rotation (SCL-*, MIR-*, ROT-*).
// Centres are absolute program coordinates of the current frame even under G91 (EX-06 REC); a
// centre axis not written is the current programmed position.
void BlockRun::step_transforms() {
    if (!group(GGroup::Scale) && !group(GGroup::Mirror) && !group(GGroup::Rotation)) return;
    auto centre_of = [&](unsigned& mask) {
        Eigen::Vector3d c = xyz(st.pos.prog_mm);
        mask = 0;
        for (int a = 0; a < 3; ++a)
            if (has_axis(a)) {
                c[a] = axis_value(a);
                mask |= 1u << a;
            }
        return c;
    };
    auto full = [&](int code) {
        fail(loc_g(code), fmt::format("{}: too many nested transforms (at most {})", gname(code),
                                      ProgramTransform::kMaxEntries));
    };
    if (g(gcode(50))) xf_mut().clear_scaling();
    if (g(gcode(51))) {
        if (st.crc_side != cutter::Side::Off)
            fail(loc_g(gcode(51)),
                 "G51 is not allowed while cutter compensation (G41/G42) is active");
        unsigned mask = 0;
        Eigen::Vector3d centre = centre_of(mask);
        Eigen::Vector3d f(1, 1, 1);
        const SourceLoc loc = loc_g(gcode(51));
        if (cfg_.v54_compat) {
            // SCL-4: I J K is the centre, P the factor (negative mirrors). S1 §3.3 says, like
            // S0 of X Y Z, that an axis whose centre is omitted keeps its previous factor.
            unsigned centre_mask = 0;
            for (int a = 0; a < 3; ++a)
                if (b_.has(kCentreLetter[a])) {
                    centre[a] = b_.get(kCentreLetter[a]) * st.units.mm_per_unit;
                    centre_mask |= 1u << a;
                }
            if (centre_mask == 0)
                fail(loc, "G51 P scales the axes whose centre (I J K) is written; none given");
            // LEX-57: S1 allows 0.000001..99.999999, and the same range negated to mirror.
            const double p = b_.has('P') ? b_.get('P') : 1.0;
            if (p == 0) fail(b_.loc_of('P'), "G51: scale factor P is 0");
            if (std::abs(p) < 0.000001 || std::abs(p) > 99.999999)
                fail(b_.loc_of('P'),
                     fmt::format("G51: scale factor P{} outside 0.000001..99.999999 (negative: "
                                 "-0.000001..-99.999999, mirrors)",
                                 p));
            for (int a = 0; a < 3; ++a)
                if (centre_mask & (1u << a)) f[a] = p;
        } else {
            const bool has_p = b_.has('P');
            const bool has_ijk = b_.has('I') || b_.has('J') || b_.has('K');
            if (has_p && has_ijk) fail(loc, "G51: use either P or I/J/K, not both");
            if (!has_p && !has_ijk) fail(loc, "G51 needs P<factor> or I/J/K factors");
            // LEX-57 / SCL-3: S0 allows 0.000001..99.999999; 0 is the alarm the manual names.
            auto check = [&](char letter) {
                const double v = b_.get(letter);
                if (v == 0)
                    fail(b_.loc_of(letter), fmt::format("G51: scale factor {} is 0", letter));
                if (v < 0.000001 || v > 99.999999)
                    fail(b_.loc_of(letter),
                         fmt::format("G51: scale factor {}{} outside 0.000001..99.999999", letter,
                                     v));
                return v;
            };
            if (has_p) {
                if (mask == 0) fail(loc, "G51 P scales the axes written in the block; none given");
                const double p = check('P');
                for (int a = 0; a < 3; ++a)
                    if (mask & (1u << a)) f[a] = p;  // SCL-2: unlisted axes keep their factor
            } else {
                for (int a = 0; a < 3; ++a)
                    if (b_.has(kCentreLetter[a])) f[a] = check(kCentreLetter[a]);
            }
        }
        if (!xf_mut().push_scale(centre, f)) full(gcode(51));
    }
    if (g(gcode(50, 1))) {
        unsigned mask = 0;
        centre_of(mask);
        xf_mut().clear_mirror(mask == 0 ? 7u : mask);  // MIR-2: none listed = all axes
    }
    if (g(gcode(51, 1))) {
        unsigned mask = 0;
        const Eigen::Vector3d c = centre_of(mask);
        if (mask == 0) fail(loc_g(gcode(51, 1)), "G51.1 needs the mirror axes (X Y Z)");
        if (!xf_mut().push_mirror(c, mask)) full(gcode(51, 1));
    }
    if (g(gcode(69))) xf_mut().pop_rotation();  // ROT-4: the most recent one only
    if (g(gcode(68))) {
        if (!b_.has('R')) fail(loc_g(gcode(68)), "G68 needs R<angle in degrees>");
        unsigned mask = 0;
        const Eigen::Vector3d c = centre_of(mask);
        if (!xf_mut().push_rotation(st.motion.plane, c, b_.get('R'))) full(gcode(68));
    }
}

// Offset writes: G92, G921, G922, G923, G992 (S0 §3.5.1, §3.5.3).
void BlockRun::step_settings_writes() {
    if (!group(GGroup::NonModal)) return;
    if (g(gcode(92))) write_g92();
    if (g(gcode(921))) write_g921();
    if (g(gcode(922))) write_g922();
    if (g(gcode(923))) write_g923();
    if (g(gcode(992))) write_g992();
}

// Moves `offset` so that the current point gets the written program coordinates, leaving the
// machine where it is: machine = T·p + O must equal T·p' + O', so O' = O + L·(p − p').
void BlockRun::shift_by_current_point(AxisVec& offset) {
    const AxisVec p = prog_of_machine(st.pos.machine_mm);
    AxisVec target = p;
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a)) target[a] = axis_value(a);
    const Eigen::Vector3d d = xf().matrix().linear() * (xyz(p) - xyz(target));
    for (int a = 0; a < kMachineAxes; ++a) offset[a] += a < 3 ? d[a] : p[a] - target[a];
}

void BlockRun::write_g92() {
    require_no_scaling(gcode(92));
    if (st.coord.g992_active)
        fail(loc_g(gcode(92)), "G92 is not allowed while a G992 temporary system is active");
    if (!any_axis_word()) fail(loc_g(gcode(92)), "G92 needs at least one axis word");
    shift_by_current_point(settings_mut().offsets.g92);
    announce_offsets();
    resync_prog();
}

void BlockRun::write_g921() {
    if (!any_axis_word()) fail(loc_g(gcode(921)), "G921 needs at least one axis word");
    shift_by_current_point(settings_mut().offsets.wcs[st.coord.wcs]);
    announce_offsets();
    resync_prog();
}

void BlockRun::write_g922() {
    const SourceLoc loc = loc_g(gcode(922));
    if (!any_axis_word()) fail(loc, "G922 needs at least one axis word");
    int p = -1;
    if (b_.has('P')) p = int_word('P', -4, 5, "G922 offset type");
    if (p == -2 || p == -3) fail(b_.loc_of('P'), "G922: P must be -4, -1 or 0..5");
    WorkOffsets& o = settings_mut().offsets;
    AxisVec& target = p == -4 ? o.common : o.wcs[p == -1 ? st.coord.wcs : p];
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a)) target[a] = axis_value(a);
    announce_offsets();
    resync_prog();
}

void BlockRun::write_g923() {
    const SourceLoc loc = loc_g(gcode(923));
    if (!b_.has('X') && !b_.has('Y') && !b_.has('Z')) fail(loc, "G923 needs at least one of X Y Z");
    const int tool = b_.has('P') ? int_word('P', 0, 99999, "G923 tool") : st.tool.current;
    if (tool == 0) fail(loc, "G923: no current tool; give P<tool>");
    ToolEntry& e = settings_mut().tools.at(tool);
    for (int a = 0; a < 3; ++a)
        if (has_axis(a)) e.offset_mm[a] = axis_value(a);
    update_tool_offset(loc);
}

// G992-3 REC: the manual's array examples put G906 before every G992 so that the interpreter
// knows where the machine really is; G992 syncs by itself unless nothing has moved since the last
// sync (so a program written the manual's way gets no second sync).
void BlockRun::write_g992() {
    const SourceLoc loc = loc_g(gcode(992));
    const bool ijk = b_.has('I') || b_.has('J') || b_.has('K');
    if (ijk && any_axis_word()) fail(loc, "G992: use either X Y Z or I J K, not both");
    if (!ijk && !any_axis_word()) fail(loc, "G992 needs X Y Z or I J K");
    if (st.moved_since_sync) emit(canon::Sync{});
    if (ijk) {
        if (cfg_.v54_compat) fail(loc, "G992 I J K is not available in NcStudio V5.4");
        for (int a = 0; a < 3; ++a)
            if (b_.has(kCentreLetter[a]))
                st.coord.g992_mm[a] += b_.get(kCentreLetter[a]) * st.units.mm_per_unit;
    } else {
        shift_by_current_point(st.coord.g992_mm);
    }
    st.coord.g992_active = true;
    announce_offsets();
    resync_prog();
}

void BlockRun::step_machine_codes() {
    if (!group(GGroup::NonModal)) return;
    if (g(gcode(28))) g28();
    if (g(gcode(904))) g904();
    if (g(gcode(906))) g906();
    if (g(gcode(916))) g916();
    if (g(gcode(918))) emit(canon::LatchClear{});
    if (g(gcode(919))) {
        if (!b_.has('H')) fail(loc_g(gcode(919)), "G919 needs H<axis> (0=X 1=Y 2=Z)");
        emit(canon::LatchStopDistance{int_word('H', 0, 2, "G919 axis")});
    }
}

// G28: rapid through the intermediate point (program coordinates) to the reference point, only
// on the axes written (REF-2, REF-3, REF-5).
void BlockRun::g28() {
    require_no_scaling(gcode(28));
    if (st.crc_side != cutter::Side::Off)
        fail(loc_g(gcode(28)), "G28 is not allowed while cutter compensation (G41/G42) is active");
    if (!any_axis_word()) fail(loc_g(gcode(28)), "G28 needs the axes to return (X Y Z)");
    AxisVec mid_prog = st.pos.prog_mm;
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a))
            mid_prog[a] = st.motion.incremental ? mid_prog[a] + axis_value(a) : axis_value(a);
    const AxisVec mid_all = to_machine(mid_prog);
    AxisVec mid = st.pos.machine_mm;
    AxisVec end = st.pos.machine_mm;
    for (int a = 0; a < kMachineAxes; ++a)
        if (has_axis(a)) {
            mid[a] = mid_all[a];
            end[a] = cfg_.reference_mm[a];
        }
    emit_rapid(mid);
    emit_rapid(end);
    resync_prog();
}

// G904 conditional move. 6th edition: FX PX LX … with optional X Y Z maximum travel. V5.4:
// X<speed> I<port> P<level>, Y J Q, Z K H (NCX-3, NCX-4).
void BlockRun::g904() {
    const SourceLoc loc = loc_g(gcode(904));
    canon::ConditionalMove cm;
    cm.flags = flags_;
    bool any = false;
    static constexpr char kV54Port[3] = {'I', 'J', 'K'};
    static constexpr char kV54Level[3] = {'P', 'Q', 'H'};
    for (int a = 0; a < 3; ++a) {
        canon::ConditionalMove::AxisWatch w;
        w.axis = a;
        const char al = kAxisLetter[a];
        if (cfg_.v54_compat) {
            const bool present = b_.has(al) || b_.has(kV54Port[a]) || b_.has(kV54Level[a]);
            if (!present) continue;
            if (!b_.has(al) || !b_.has(kV54Port[a]) || !b_.has(kV54Level[a]))
                fail(loc, fmt::format("G904: axis {} needs {}, {} and {}", al, al, kV54Port[a],
                                      kV54Level[a]));
            w.speed_mm_s = mm(al) / 60.0;
            w.port = int_word(kV54Port[a], 0, 1 << 20, "G904 input");
            w.level = int_word(kV54Level[a], 0, 1, "G904 level") == 1;
        } else {
            const auto& f = b_.kw.f_axis[a];
            const auto& p = b_.kw.p_axis[a];
            const auto& l = b_.kw.l_axis[a];
            if (!f && !p && !l) {
                if (b_.has(al))
                    fail(b_.loc_of(al), fmt::format("G904: {0} travel without F{0} P{0} L{0}", al));
                continue;
            }
            if (!f || !p || !l)
                fail(loc, fmt::format("G904: axis {0} needs F{0}, P{0} and L{0}", al));
            if (*l != 0 && *l != 1) fail(loc, fmt::format("G904: L{} must be 0 or 1", al));
            w.speed_mm_s = *f * st.units.mm_per_unit / 60.0;
            w.port = *p;
            w.level = *l == 1;
            if (b_.has(al)) w.max_travel_mm = std::abs(mm(al));
        }
        if (w.speed_mm_s == 0) fail(loc, fmt::format("G904: axis {} has speed 0", al));
        cm.axes[a] = w;
        any = true;
    }
    if (!any) fail(loc, "G904 needs at least one axis (FX PX LX …)");
    emit(cm);
    simulate_g904(cm, loc);
}

// Where the standalone model says a G904 axis stops (BackendConfig::g904_trip_mm). A trigger
// behind the move or beyond the maximum travel is the alarm NCX-3 recommends.
void BlockRun::simulate_g904(const canon::ConditionalMove& cm, const SourceLoc& loc) {
    bool moved = false;
    for (const auto& w : cm.axes) {
        if (!w || !cfg_.g904_trip_mm[w->axis]) continue;
        const double from = st.pos.machine_mm[w->axis];
        const double to = *cfg_.g904_trip_mm[w->axis];
        const char al = kAxisLetter[w->axis];
        if ((to - from) * w->speed_mm_s < 0)
            fail(loc, fmt::format("G904: {} moves away from where its input changes ({} mm)", al,
                                  fmt_num(to)));
        if (w->max_travel_mm && std::abs(to - from) > *w->max_travel_mm)
            fail(loc, fmt::format("G904: {} travelled {} mm without the input changing", al,
                                  fmt_num(*w->max_travel_mm)));
        st.pos.machine_mm[w->axis] = to;
        moved = true;
    }
    if (moved) resync_prog();
}

void BlockRun::g906() {
    const SourceLoc loc = loc_g(gcode(906));
    if (!b_.kw.plc && !b_.kw.level && !b_.has('P')) {
        emit(canon::Sync{});
        return;
    }
    if (!b_.kw.plc || !b_.kw.level || !b_.has('P'))
        fail(loc, "G906 with a port needs PLC[addr] LEVEL<0|1> P<timeout ms>");
    if (*b_.kw.level != 0 && *b_.kw.level != 1) fail(loc, "G906: LEVEL must be 0 or 1");
    const double ms = b_.get('P');
    if (ms < 0) fail(b_.loc_of('P'), "G906: negative timeout");
    emit(canon::WaitInput{*b_.kw.plc, *b_.kw.level == 1, ms / 1000.0});
}

void BlockRun::g916() {
    const SourceLoc loc = loc_g(gcode(916));
    bool any = false;
    for (int a = 0; a < 3; ++a) {
        const auto& p = b_.kw.p_axis[a];
        const auto& l = b_.kw.l_axis[a];
        if (!p && !l) continue;
        if (!p || !l)
            fail(loc, fmt::format("G916: axis {0} needs P{0}[addr] and L{0}", kAxisLetter[a]));
        if (*l != 0 && *l != 1) fail(loc, fmt::format("G916: L{} must be 0 or 1", kAxisLetter[a]));
        emit(canon::LatchConfig{a, *p, *l == 1});
        any = true;
    }
    if (!any) fail(loc, "G916 needs PX[addr] LX<0|1> (or Y/Z)");
}

}  // namespace interp::back
