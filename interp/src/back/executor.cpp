// Block execution: a block runs as an ordered list of steps (units, feed, spindle, tool, I/O,
// dwell, plane, length comp, work system, distance mode, transforms, settings writes, the
// machine-facing extended codes, motion, stops), each a small function that looks only at its own
// codes — the order LinuxCNC's convert_* chain and the NcStudio manual imply. Codes are found
// through tables that give each code its modal group; a code in no table is an error naming it.
#include "interp/executor.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "interp/arc.hpp"
#include "interp/hole_patterns.hpp"

namespace interp {

namespace {

enum class GGroup {
    Motion,
    Plane,
    Units,
    Distance,
    ToolLength,
    Wcs,
    Scale,
    Mirror,
    Rotation,
    NonModal,
    FeedMode,
    Cycle,        // G73 … G89, G80
    CycleReturn,  // G98 / G99
    Crc,          // G40 / G41 / G42
    Flag,
};

struct GInfo {
    int code;
    GGroup group;
    bool uses_axes;  // the block's axis words belong to this code, not to a motion
};

constexpr GInfo kGTable[] = {
    {gcode(0), GGroup::Motion, false},       {gcode(1), GGroup::Motion, false},
    {gcode(2), GGroup::Motion, false},       {gcode(3), GGroup::Motion, false},
    {gcode(4), GGroup::NonModal, false},     {gcode(17), GGroup::Plane, false},
    {gcode(18), GGroup::Plane, false},       {gcode(19), GGroup::Plane, false},
    {gcode(20), GGroup::Units, false},       {gcode(21), GGroup::Units, false},
    {gcode(70), GGroup::Units, false},       {gcode(71), GGroup::Units, false},
    {gcode(28), GGroup::NonModal, true},     {gcode(43), GGroup::ToolLength, false},
    {gcode(44), GGroup::ToolLength, false},  {gcode(49), GGroup::ToolLength, false},
    {gcode(50), GGroup::Scale, false},       {gcode(51), GGroup::Scale, true},
    {gcode(50, 1), GGroup::Mirror, true},    {gcode(51, 1), GGroup::Mirror, true},
    {gcode(53), GGroup::Flag, false},        {gcode(54), GGroup::Wcs, false},
    {gcode(55), GGroup::Wcs, false},         {gcode(56), GGroup::Wcs, false},
    {gcode(57), GGroup::Wcs, false},         {gcode(58), GGroup::Wcs, false},
    {gcode(59), GGroup::Wcs, false},         {gcode(68), GGroup::Rotation, true},
    {gcode(69), GGroup::Rotation, false},    {gcode(90), GGroup::Distance, false},
    {gcode(91), GGroup::Distance, false},    {gcode(92), GGroup::NonModal, true},
    {gcode(94), GGroup::FeedMode, false},    {gcode(903), GGroup::Flag, false},
    {gcode(904), GGroup::NonModal, true},    {gcode(905), GGroup::Flag, false},
    {gcode(906), GGroup::NonModal, false},   {gcode(907), GGroup::Flag, false},
    {gcode(908), GGroup::Flag, false},       {gcode(916), GGroup::NonModal, false},
    {gcode(73), GGroup::Cycle, false},       {gcode(74), GGroup::Cycle, false},
    {gcode(76), GGroup::Cycle, false},       {gcode(80), GGroup::Cycle, false},
    {gcode(81), GGroup::Cycle, false},       {gcode(82), GGroup::Cycle, false},
    {gcode(83), GGroup::Cycle, false},       {gcode(84), GGroup::Cycle, false},
    {gcode(85), GGroup::Cycle, false},       {gcode(86), GGroup::Cycle, false},
    {gcode(87), GGroup::Cycle, false},       {gcode(88), GGroup::Cycle, false},
    {gcode(89), GGroup::Cycle, false},       {gcode(98), GGroup::CycleReturn, false},
    {gcode(99), GGroup::CycleReturn, false}, {gcode(34), GGroup::NonModal, true},
    {gcode(35), GGroup::NonModal, true},     {gcode(36), GGroup::NonModal, true},
    {gcode(37), GGroup::NonModal, true},     {gcode(40), GGroup::Crc, false},
    {gcode(41), GGroup::Crc, false},         {gcode(42), GGroup::Crc, false},
    {gcode(918), GGroup::NonModal, false},   {gcode(919), GGroup::NonModal, false},
    {gcode(921), GGroup::NonModal, true},    {gcode(922), GGroup::NonModal, true},
    {gcode(923), GGroup::NonModal, true},    {gcode(992), GGroup::NonModal, true},
};

const GInfo* find_g(int code) {
    for (const GInfo& g : kGTable)
        if (g.code == code) return &g;
    return nullptr;
}

enum class MGroup { Stop, Spindle, Coolant, Clamp, ToolChange, Own };

struct MInfo {
    int code;
    MGroup group;
};

constexpr MInfo kMTable[] = {
    {0, MGroup::Stop},         {1, MGroup::Stop},    {2, MGroup::Stop},    {30, MGroup::Stop},
    {3, MGroup::Spindle},      {4, MGroup::Spindle}, {5, MGroup::Spindle}, {6, MGroup::ToolChange},
    {903, MGroup::ToolChange}, {8, MGroup::Coolant}, {9, MGroup::Coolant}, {10, MGroup::Clamp},
    {11, MGroup::Clamp},       {801, MGroup::Own},   {802, MGroup::Own},   {901, MGroup::Own},
    {902, MGroup::Own},
};

const MInfo* find_m(int code) {
    for (const MInfo& m : kMTable)
        if (m.code == code) return &m;
    return nullptr;
}

std::string gname(int code) {
    const int whole = code / 10;
    const int tenth = code % 10;
    std::string s = whole < 10 ? fmt::format("G{:02d}", whole) : fmt::format("G{}", whole);
    if (tenth != 0) s += fmt::format(".{}", tenth);
    return s;
}

std::string mname(int code) {
    return code < 10 ? fmt::format("M{:02d}", code) : fmt::format("M{}", code);
}

constexpr char kAxisLetter[kMachineAxes] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
constexpr char kCentreLetter[3] = {'I', 'J', 'K'};

Eigen::Vector3d xyz(const AxisVec& v) {
    return {v[0], v[1], v[2]};
}

// One block's execution against copies of the state. Steps throw interp::Error; the caller
// commits the copies only when run() returns.
class BlockRun {
  public:
    BlockRun(const Block& b, const BackendConfig& cfg, const ExecState& st,
             const ProgramTransform& xf, const Settings& settings, std::vector<Canon>& out)
        : st(st), b_(b), cfg_(cfg), base_xf_(xf), base_settings_(settings), out_(out) {}

    void run();

    ExecState st;
    std::optional<ProgramTransform> xf_copy;
    std::optional<Settings> settings_copy;

  private:
    using Step = void (BlockRun::*)();
    static const Step kSteps[];

    // --- steps, in execution order ---
    void validate();
    void announce_start();
    void step_units();
    void step_feed();
    void step_spindle_speed();
    void step_tool();
    void step_spindle();
    void step_coolant();
    void step_io();
    void step_dwell();
    void step_plane();
    void announce_units();
    void step_tool_length();
    void step_cutter_comp();
    void step_crc_effective();
    void step_wcs();
    void step_distance();
    void step_transforms();
    void step_settings_writes();
    void step_machine_codes();
    void step_cycle_modes();
    void step_motion();
    void step_stop();

    // --- helpers ---
    [[noreturn]] void fail(const SourceLoc& loc, const std::string& why) const {
        throw Error(loc, why);
    }
    SourceLoc loc_g(int code) const {
        for (std::size_t i = 0; i < b_.g.size(); ++i)
            if (b_.g[i] == code) return {b_.loc.file, b_.loc.line, b_.g_col[i]};
        return b_.loc;
    }
    SourceLoc loc_m(int code) const {
        for (std::size_t i = 0; i < b_.m.size(); ++i)
            if (b_.m[i] == code) return {b_.loc.file, b_.loc.line, b_.m_col[i]};
        return b_.loc;
    }
    bool g(int code) const { return b_.has_g(code); }
    // Groups present in the block (set by validate): most blocks skip most steps at once.
    bool group(GGroup grp) const { return (groups_ & (1u << static_cast<unsigned>(grp))) != 0; }
    bool m(int code) const { return b_.has_m(code); }
    template <typename T>
    void emit(T&& cmd) {
        out_.push_back(Canon{b_.loc, CanonCommand(std::forward<T>(cmd))});
    }
    const ProgramTransform& xf() const { return xf_copy ? *xf_copy : base_xf_; }
    ProgramTransform& xf_mut() {
        if (!xf_copy) xf_copy = base_xf_;
        return *xf_copy;
    }
    const Settings& settings() const { return settings_copy ? *settings_copy : base_settings_; }
    Settings& settings_mut() {
        if (!settings_copy) settings_copy = base_settings_;
        return *settings_copy;
    }
    double mm(char letter) const { return b_.get(letter) * st.units.mm_per_unit; }
    // An axis word in mm (linear) or degrees (rotary).
    double axis_value(int axis) const {
        const double v = b_.get(kAxisLetter[axis]);
        return axis < 3 ? v * st.units.mm_per_unit : v;
    }
    bool has_axis(int axis) const { return b_.has(kAxisLetter[axis]); }
    bool any_axis_word() const {
        for (int a = 0; a < kMachineAxes; ++a)
            if (has_axis(a)) return true;
        return false;
    }
    int int_word(char letter, int lo, int hi, const char* what) const {
        const double v = b_.get(letter);
        if (v != std::floor(v) || v < lo || v > hi)
            fail(b_.loc_of(letter), fmt::format("{}: {}{} must be an integer in {}..{}", what,
                                                letter, fmt_num(v), lo, hi));
        return static_cast<int>(v);
    }

    AxisVec offset_total() const;
    AxisVec to_machine(const AxisVec& prog) const;
    AxisVec prog_of_machine(const AxisVec& machine) const;
    void resync_prog() { st.pos.prog_mm = prog_of_machine(st.pos.machine_mm); }
    void announce_offsets();
    void update_tool_offset(const SourceLoc& loc);
    AxisVec programmed_target() const;
    void require_no_scaling(int code) const;
    void require_feed(const char* what);

    void emit_rapid(const AxisVec& end);
    void move_line(bool rapid, bool machine_coords);
    void move_arc(bool ccw);
    void g28();
    void g904();
    void simulate_g904(const canon::ConditionalMove& cm, const SourceLoc& loc);
    void g906();
    void g916();
    void write_g92();
    void write_g921();
    void write_g922();
    void write_g923();
    void write_g992();
    void shift_by_current_point(AxisVec& offset);
    void program_end(bool rewind);
    cycles::BlockContext cycle_context() const;
    cycles::CycleWords cycle_words() const;
    void run_cycle();
    void run_hole_pattern();
    void emit_cycle_steps(const cycles::Expansion& e);

    const Block& b_;
    const BackendConfig& cfg_;
    const ProgramTransform& base_xf_;
    const Settings& base_settings_;
    std::vector<Canon>& out_;
    canon::MoveFlags flags_;
    std::optional<int> motion_code_;  // G00..G03 written in this block
    std::optional<int> cycle_code_;   // G73..G89 or G80 written in this block
    const GInfo* axis_user_ = nullptr;
    unsigned groups_ = 0;
};

const BlockRun::Step BlockRun::kSteps[] = {
    &BlockRun::validate,           &BlockRun::announce_start,     &BlockRun::step_units,
    &BlockRun::step_feed,          &BlockRun::step_spindle_speed, &BlockRun::step_tool,
    &BlockRun::step_spindle,       &BlockRun::step_coolant,       &BlockRun::step_io,
    &BlockRun::step_dwell,         &BlockRun::step_plane,         &BlockRun::announce_units,
    &BlockRun::step_cutter_comp,   &BlockRun::step_tool_length,   &BlockRun::step_wcs,
    &BlockRun::step_distance,      &BlockRun::step_transforms,    &BlockRun::step_settings_writes,
    &BlockRun::step_machine_codes, &BlockRun::step_cycle_modes,   &BlockRun::step_motion,
    &BlockRun::step_stop,          &BlockRun::step_crc_effective,
};

void BlockRun::run() {
    for (Step s : kSteps) (this->*s)();
}

// ---------------------------------------------------------------------------------------------
// Validation: unknown codes, two codes of one modal group, G90 with G91 (ABS-2).

void BlockRun::validate() {
    std::array<int, 16> seen_group;
    seen_group.fill(-1);
    for (std::size_t i = 0; i < b_.g.size(); ++i) {
        const int code = b_.g[i];
        const GInfo* info = find_g(code);
        const SourceLoc loc{b_.loc.file, b_.loc.line, b_.g_col[i]};
        if (!info) fail(loc, fmt::format("unsupported G code {}", gname(code)));
        if (code == gcode(91) && g(gcode(90))) fail(loc, "G90 and G91 in the same block");
        const int grp = static_cast<int>(info->group);
        groups_ |= 1u << static_cast<unsigned>(grp);
        if (info->group != GGroup::Flag) {
            if (seen_group[grp] >= 0)
                fail(loc, fmt::format("{} and {} are in the same modal group",
                                      gname(seen_group[grp]), gname(code)));
            seen_group[grp] = code;
        }
        if (info->group == GGroup::Motion) motion_code_ = code;
        if (info->group == GGroup::Cycle) cycle_code_ = code;
        if (info->uses_axes) {
            if (axis_user_)
                fail(loc, fmt::format("{} and {} both use the axis words", gname(axis_user_->code),
                                      gname(code)));
            axis_user_ = info;
        }
    }
    if (motion_code_ && cycle_code_ && *cycle_code_ != gcode(80))
        fail(loc_g(*cycle_code_), fmt::format("{} and {} cannot share a block",
                                              gname(*motion_code_), gname(*cycle_code_)));
    if (axis_user_ && cycle_code_ && *cycle_code_ != gcode(80) &&
        !(axis_user_->code >= gcode(34) && axis_user_->code <= gcode(37)))
        fail(loc_g(*cycle_code_), fmt::format("{} and {} both use the axis words",
                                              gname(axis_user_->code), gname(*cycle_code_)));
    std::array<int, 8> seen_m;
    seen_m.fill(-1);
    for (std::size_t i = 0; i < b_.m.size(); ++i) {
        const int code = b_.m[i];
        const MInfo* info = find_m(code);
        const SourceLoc loc{b_.loc.file, b_.loc.line, b_.m_col[i]};
        if (!info) fail(loc, fmt::format("unsupported M code {}", mname(code)));
        const int grp = static_cast<int>(info->group);
        if (info->group != MGroup::Own) {
            if (seen_m[grp] >= 0)
                fail(loc, fmt::format("{} and {} are in the same modal group", mname(seen_m[grp]),
                                      mname(code)));
            seen_m[grp] = code;
        }
    }
    if (b_.msg && !m(801)) fail(b_.loc, "MSG is only allowed with M801");
    flags_.force_full_override = g(gcode(903));
    flags_.force_programmed_feed = g(gcode(905));
    flags_.rotary_shortest_path = g(gcode(907));
    flags_.rotary_degrees = g(gcode(908));
}

// The first block announces where the offsets stand, so a consumer that needs work coordinates
// (the LinuxCNC-format printer, a UI) can follow from the first move on.
void BlockRun::announce_start() {
    if (st.started) return;
    st.started = true;
    announce_offsets();
}

AxisVec BlockRun::offset_total() const {
    const WorkOffsets& o = settings().offsets;
    AxisVec t{};
    for (int a = 0; a < kMachineAxes; ++a) {
        t[a] = o.wcs[st.coord.wcs][a] + o.common[a] + o.g92[a] + st.coord.g992_mm[a];
        if (a < 3) t[a] += st.tool.offset_mm[a];
    }
    return t;
}

AxisVec BlockRun::to_machine(const AxisVec& prog) const {
    const AxisVec off = offset_total();
    const Eigen::Vector3d w = xf().apply(xyz(prog));
    AxisVec m{};
    for (int a = 0; a < kMachineAxes; ++a) m[a] = (a < 3 ? w[a] : prog[a]) + off[a];
    return m;
}

AxisVec BlockRun::prog_of_machine(const AxisVec& machine) const {
    const AxisVec off = offset_total();
    AxisVec w{};
    for (int a = 0; a < kMachineAxes; ++a) w[a] = machine[a] - off[a];
    const Eigen::Vector3d p = xf().identity() ? xyz(w) : xf().inverse(xyz(w));
    for (int a = 0; a < 3; ++a) w[a] = p[a];
    return w;
}

void BlockRun::announce_offsets() {
    const WorkOffsets& o = settings().offsets;
    canon::Offsets c;
    c.wcs = st.coord.wcs + 1;
    for (int a = 0; a < kMachineAxes; ++a) {
        c.wcs_mm[a] = o.wcs[st.coord.wcs][a] + o.common[a];
        c.shift_mm[a] = o.g92[a] + st.coord.g992_mm[a];
    }
    emit(c);
}

// Recomputes the active tool offset vector after G43/G44/G49, a tool change or G923, and
// announces it when it changed. Nothing moves in this block unless it has motion words.
void BlockRun::update_tool_offset(const SourceLoc& loc) {
    std::array<double, 3> v{};
    if (st.tool.length_mode != ToolLengthMode::Off) {
        const int reg = st.tool.h_register.value_or(st.tool.current);
        if (reg != 0) {
            const ToolEntry* e = settings().tools.find(reg);
            if (!e)
                fail(loc, fmt::format("tool length compensation: tool {} is not in the tool table",
                                      reg));
            const double sign = st.tool.length_mode == ToolLengthMode::Plus ? 1.0 : -1.0;
            for (int a = 0; a < 3; ++a) v[a] = sign * e->offset_mm[a];
        }
    }
    if (v == st.tool.offset_mm) return;
    st.tool.offset_mm = v;
    emit(canon::ToolOffset{v});
    // The programmed position is kept, so the next move (absolute or incremental) carries the new
    // offset, as on NcStudio/Fanuc: `G91 G43 Z-17 H01` moves 17 plus the tool length, and a later
    // G49 block takes the length back out (FEATURES EX-18 returns to its start).
}

// ---------------------------------------------------------------------------------------------

void BlockRun::step_units() {
    if (!group(GGroup::Units)) return;
    double mpu = st.units.mm_per_unit;
    if (g(gcode(20)) || g(gcode(70))) mpu = 25.4;
    if (g(gcode(21)) || g(gcode(71))) mpu = 1.0;
    st.units.mm_per_unit = mpu;
}

// Announced after the plane, in LinuxCNC's order, though the value applied from the start of the
// block (F and every length of the block are in the new units).
void BlockRun::announce_units() {
    if (g(gcode(20)) || g(gcode(70)) || g(gcode(21)) || g(gcode(71)))
        emit(canon::Units{st.units.inch()});
}

// F in a block whose motion mode is G00 sets the rapid speed only (G00-3).
void BlockRun::step_feed() {
    if (g(gcode(94))) emit(canon::SetFeedMode{true});
    if (!b_.has('F')) return;
    const double f = b_.get('F');
    if (f < 0) fail(b_.loc_of('F'), fmt::format("negative feed rate F{}", fmt_num(f)));
    const double f_mm_s = f * st.units.mm_per_unit / 60.0;
    // A canned-cycle block's F is the drilling feed even though G00 is the modal motion.
    const bool cycle_block =
        (cycle_code_ && *cycle_code_ != gcode(80)) || (st.cycle.active() && !motion_code_);
    const bool rapid_mode = !cycle_block && (motion_code_ ? *motion_code_ == gcode(0)
                                                          : st.motion.motion == Motion::Rapid);
    if (rapid_mode && !g(gcode(904))) {
        double r = f_mm_s;
        if (cfg_.max_rapid_mm_s > 0) r = std::min(r, cfg_.max_rapid_mm_s);
        st.feed.rapid_mm_s = r;
        emit(canon::SetRapidRate{r});
        if (st.feed.feed_set) return;  // G00-3 REC: a first bare F also primes the cutting feed
    }
    st.feed.feed_mm_s = f_mm_s;
    st.feed.feed_set = true;
    emit(canon::SetFeedRate{f_mm_s});
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
        seconds = b_.get('P') / 1000.0;  // DW-1: P in milliseconds
        if (!(b_.integer_literal_mask & (1u << letter_index('P'))))
            emit(canon::Warning{"G04 P is in milliseconds; the fraction is kept"});
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
    if (g(gcode(40))) st.crc_side = cutter::Side::Off;
    if (g(gcode(41))) st.crc_side = cutter::Side::Left;
    if (g(gcode(42))) st.crc_side = cutter::Side::Right;
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

void BlockRun::step_distance() {
    if (!group(GGroup::Distance)) return;
    if (g(gcode(90))) st.motion.incremental = false;
    if (g(gcode(91))) st.motion.incremental = true;
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
            // SCL-4: I J K is the centre, P the factor for every axis (negative mirrors).
            for (int a = 0; a < 3; ++a)
                if (b_.has(kCentreLetter[a]))
                    centre[a] = b_.get(kCentreLetter[a]) * st.units.mm_per_unit;
            const double p = b_.has('P') ? b_.get('P') : 1.0;
            if (p == 0 || std::abs(p) > 99.999999)
                fail(b_.has('P') ? b_.loc_of('P') : loc,
                     fmt::format("G51: scale factor P{} out of range", fmt_num(p)));
            f = Eigen::Vector3d(p, p, p);
        } else {
            const bool has_p = b_.has('P');
            const bool has_ijk = b_.has('I') || b_.has('J') || b_.has('K');
            if (has_p && has_ijk) fail(loc, "G51: use either P or I/J/K, not both");
            if (!has_p && !has_ijk) fail(loc, "G51 needs P<factor> or I/J/K factors");
            auto check = [&](char letter) {
                const double v = b_.get(letter);
                if (v == 0)
                    fail(b_.loc_of(letter), fmt::format("G51: scale factor {} is 0", letter));
                if (v < 0.000001 || v > 99.999999)
                    fail(b_.loc_of(letter),
                         fmt::format("G51: scale factor {}{} outside 0.000001..99.999999", letter,
                                     fmt_num(v)));
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

void BlockRun::write_g992() {
    const SourceLoc loc = loc_g(gcode(992));
    const bool ijk = b_.has('I') || b_.has('J') || b_.has('K');
    if (ijk && any_axis_word()) fail(loc, "G992: use either X Y Z or I J K, not both");
    if (!ijk && !any_axis_word()) fail(loc, "G992 needs X Y Z or I J K");
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

void BlockRun::require_feed(const char* what) {
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
    if (machine_coords) {
        end = st.pos.machine_mm;
        for (int a = 0; a < kMachineAxes; ++a)
            if (has_axis(a))  // MCS-3 REC: tool length compensation stays active under G53
                end[a] = axis_value(a) + (a < 3 ? st.tool.offset_mm[a] : 0.0);
    } else {
        end = to_machine(programmed_target());
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
        st.pos.prog_mm = programmed_target();
}

void BlockRun::move_arc(bool ccw) {
    require_feed("an arc");
    const PlaneAxes pa = plane_axes(st.motion.plane);
    // The arc starts where the machine is, seen in the current program frame.
    const AxisVec start = prog_of_machine(st.pos.machine_mm);
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
    ArcResult r;
    if (std::string why = solve_arc(in, r); !why.empty()) fail(b_.loc, why);

    // ARC-9 (V5.4): K is the lead of a multi-turn helix in G17 when it is not a centre word.
    int extra_turns = 0;
    if (cfg_.v54_compat && st.motion.plane == Plane::XY && b_.has('K') && has_r) {
        const double lead = std::abs(b_.get('K') * st.units.mm_per_unit);
        const double dz = std::abs(end[2] - start[2]);
        if (lead > 0)
            extra_turns = std::max(
                0, static_cast<int>(std::lround(dz / lead - r.sweep_rad / (2 * std::numbers::pi))));
    }

    // Into machine coordinates: the plane must stay a machine plane and circles stay circles.
    const Eigen::Matrix3d L = xf().matrix().linear();
    const Eigen::Vector3d n = L.col(pa.normal);
    int target_normal = -1;
    for (int k = 0; k < 3; ++k) {
        const double rest = n.norm() - std::abs(n[k]);
        if (std::abs(rest) < 1e-9 * n.norm()) target_normal = k;
    }
    if (target_normal < 0)
        fail(b_.loc, "arc plane is not a machine plane after the programmed rotation");
    const Plane mp = target_normal == 2 ? Plane::XY : target_normal == 1 ? Plane::ZX : Plane::YZ;
    const PlaneAxes ma = plane_axes(mp);
    Eigen::Matrix2d B;
    B << L(ma.first, pa.first), L(ma.first, pa.second), L(ma.second, pa.first),
        L(ma.second, pa.second);
    const Eigen::Matrix2d BtB = B.transpose() * B;
    const double s2 = 0.5 * BtB.trace();
    if (std::abs(BtB(0, 1)) > 1e-9 * s2 || std::abs(BtB(0, 0) - BtB(1, 1)) > 1e-9 * s2)
        fail(b_.loc, "non-uniform scaling of arc (different G51 factors on the plane axes)");
    const bool flipped = B.determinant() < 0;  // a mirror turns G02 into G03 (ARC-14)

    AxisVec centre_prog = start;
    centre_prog[pa.first] = r.centre.x();
    centre_prog[pa.second] = r.centre.y();
    const AxisVec centre_m = to_machine(centre_prog);
    const AxisVec end_m = to_machine(end);

    canon::Arc arc;
    arc.plane = mp;
    arc.end_mm = end_m;
    arc.centre_mm = {centre_m[0], centre_m[1], centre_m[2]};
    arc.centre_mm[ma.normal] = st.pos.machine_mm[ma.normal];
    const bool machine_ccw = ccw != flipped;
    arc.turns = (1 + extra_turns) * (machine_ccw ? 1 : -1);
    arc.flags = flags_;
    emit(arc);
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
    if (b_.has('P')) w.p_ms = b_.get('P');
    // C-14: NcStudio documents K and uses L in its examples; both are the repeat count.
    if (b_.has('K'))
        w.k = std::lround(b_.get('K'));
    else if (b_.has('L'))
        w.k = std::lround(b_.get('L'));
    return w;
}

void BlockRun::run_cycle() {
    if (!st.feed.feed_set) require_feed("a canned cycle");
    std::optional<cycles::CycleCode> code;
    if (cycle_code_ && *cycle_code_ != gcode(80))
        code = cycles::cycle_code_from_g(*cycle_code_ / 10);
    try {
        const cycles::Expansion e =
            st.cycle.run_block(code, cycle_words(), cycle_context(), cfg_.cycles);
        emit_cycle_steps(e);
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
    if (b_.has('K')) w.k = std::lround(b_.get('K'));
    try {
        const auto holes =
            cycles::hole_pattern(code / 10, w, st.motion.incremental,
                                 {st.pos.prog_mm[0], st.pos.prog_mm[1]}, st.cycle.active());
        emit_cycle_steps(st.cycle.drill_at(holes, cycle_context(), cfg_.cycles));
    } catch (const cycles::CycleError& e) {
        fail(loc_g(code), e.what());
    }
}

void BlockRun::emit_cycle_steps(const cycles::Expansion& e) {
    for (const std::string& w : e.warnings) emit(canon::Warning{w});
    const SpindleDir dir_at_start = st.spindle.dir;
    const double modal_feed = st.feed.feed_mm_s;
    double announced_feed = modal_feed;
    auto set_dir = [&](SpindleDir d) {
        st.spindle.dir = d;
        emit(canon::Spindle{d});
    };
    for (const cycles::Step& step : e.steps) {
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
                    emit(canon::SpindleOrient{});
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
    st.coord.g992_mm = {};
    st.coord.g992_active = false;
    st.motion = MotionModal{};
    st.units = UnitsModal{};
    st.feed.rapid_mm_s = 0;
    st.tool.length_mode = ToolLengthMode::Off;
    st.tool.h_register.reset();
    const std::array<double, 3> before = st.tool.offset_mm;
    st.tool.offset_mm = {};
    if (before != st.tool.offset_mm) emit(canon::ToolOffset{st.tool.offset_mm});
    if (cfg_.end_stops_spindle) {
        if (st.spindle.dir != SpindleDir::Stop) emit(canon::Spindle{SpindleDir::Stop});
        if (st.coolant.flood) emit(canon::Coolant{false});
        st.spindle.dir = SpindleDir::Stop;
        st.coolant.flood = false;
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

}  // namespace

// ---------------------------------------------------------------------------------------------

Executor::Executor(CanonSink& sink, BackendConfig cfg, Settings settings)
    : sink_(sink), cfg_(std::move(cfg)), settings_(std::move(settings)), crc_(sink, cfg_.cutter) {
    out_.reserve(16);
}

void Executor::execute(const Block& block) {
    out_.clear();
    BlockRun run(block, cfg_, state_, xf_, settings_, out_);
    run.run();  // throws: nothing below runs, nothing was changed
    commit(std::move(run.st), std::move(run.xf_copy), std::move(run.settings_copy), out_);
}

void Executor::end_of_input(const SourceLoc& loc) {
    Block b;
    b.loc = loc;
    b.m.push_back(2);
    b.m_col.push_back(loc.col);
    execute(b);
}

void Executor::commit(ExecState&& st, std::optional<ProgramTransform>&& xf,
                      std::optional<Settings>&& settings, std::vector<Canon>& out) {
    const AxisVec machine_before = state_.pos.machine_mm;
    state_ = st;
    if (xf) xf_ = std::move(*xf);
    const bool settings_changed = settings && !(*settings == settings_);
    if (settings) settings_ = std::move(*settings);
    if (settings_changed && settings_listener_) settings_listener_(settings_);
    if (crc_.engaged() || state_.crc.side != cutter::Side::Off)
        crc_.pass(out, state_.crc, machine_before);  // may throw a look-ahead error
    else
        for (const Canon& c : out) sink_.emit(c);
}

double Executor::machine_pos_mm(Axis axis) {
    return state_.pos.machine_mm[static_cast<int>(axis)];
}

double Executor::work_pos_mm(Axis axis) {
    const int a = static_cast<int>(axis);
    const WorkOffsets& o = settings_.offsets;
    double off = o.wcs[state_.coord.wcs][a] + o.common[a] + o.g92[a] + state_.coord.g992_mm[a];
    if (a < 3) off += state_.tool.offset_mm[a];
    return state_.pos.machine_mm[a] - off;
}

double Executor::spindle_rpm() {
    return state_.spindle.dir == SpindleDir::Stop ? 0.0 : state_.spindle.rpm;
}

std::optional<double> Executor::setting(std::string_view name) {
    if (auto it = settings_.params.find(name); it != settings_.params.end()) return it->second;
    if (auto it = cfg_.machine_settings.find(name); it != cfg_.machine_settings.end())
        return it->second;
    return std::nullopt;
}

void Executor::set_persistent_param(std::string_view name, double value) {
    auto it = settings_.params.find(name);
    if (it != settings_.params.end() && it->second == value) return;
    settings_.params[std::string(name)] = value;
    if (settings_listener_) settings_listener_(settings_);
}

}  // namespace interp
