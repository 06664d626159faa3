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

#include "block_run.hpp"

namespace interp::back {

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
    {gcode(9), GGroup::Flag, false},         {gcode(61), GGroup::PathMode, false},
    {gcode(64), GGroup::PathMode, false},
};

const GInfo* find_g(int code) {
    for (const GInfo& g : kGTable)
        if (g.code == code) return &g;
    return nullptr;
}

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

// The steps in execution order. Called directly rather than through a table of member pointers:
// a block runs all 24 of them, and most return at once.
void BlockRun::run() {
    validate();
    announce_start();
    step_units();
    step_feed();
    step_spindle_speed();
    step_tool();
    step_spindle();
    step_coolant();
    step_io();
    step_dwell();
    step_plane();
    announce_units();
    step_cutter_comp();
    step_tool_length();
    step_wcs();
    step_path_mode();
    step_distance();
    step_transforms();
    step_settings_writes();
    step_machine_codes();
    step_cycle_modes();
    step_motion();
    step_stop();
    step_crc_effective();
}

// ---------------------------------------------------------------------------------------------
// Validation: unknown codes, two codes of one modal group, G90 with G91 (ABS-2).

void BlockRun::validate() {
    std::array<int, static_cast<int>(GGroup::Flag) + 1> seen_group;
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
    if (group(GGroup::Flag)) {  // G09, G53, G903, G905, G907, G908: most blocks have none
        flags_.force_full_override = g(gcode(903));
        flags_.force_programmed_feed = g(gcode(905));
        flags_.rotary_shortest_path = g(gcode(907));
        flags_.rotary_degrees = g(gcode(908));
        flags_.exact_stop = g(gcode(9));
    }
    require_no_mirror_coord_change();
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

AxisVec BlockRun::to_machine(const AxisVec& prog, const AxisVec& off) const {
    AxisVec m{};
    if (xf().identity()) {  // the common case: no affine product needed
        for (int a = 0; a < kMachineAxes; ++a) m[a] = prog[a] + off[a];
        return m;
    }
    const Eigen::Vector3d w = xf().apply(xyz(prog));
    for (int a = 0; a < kMachineAxes; ++a) m[a] = (a < 3 ? w[a] : prog[a]) + off[a];
    return m;
}

AxisVec BlockRun::prog_of_machine(const AxisVec& machine, const AxisVec& off) const {
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

}  // namespace interp::back

namespace interp {

using back::BlockRun;

Executor::Executor(CanonSink& sink, BackendConfig cfg, Settings settings)
    : sink_(sink), cfg_(std::move(cfg)), settings_(std::move(settings)), crc_(sink, cfg_.cutter) {
    out_.reserve(16);
}

void Executor::execute(const Block& block) {
    out_.clear();
    BlockRun run(block, cfg_, state_, xf_, settings_, out_);
    run.run();  // throws: nothing below runs, nothing was changed
    if (!run.has_pending_holes()) {
        commit(std::move(run.st), std::move(run.xf_copy), std::move(run.settings_copy), out_);
        return;
    }
    // A canned-cycle block with more holes (K repeats, G34–G37) was validated with its first
    // hole; the others are made and passed on one at a time, so memory stays flat (issue 4).
    commit(ExecState(run.st), std::optional<ProgramTransform>(run.xf_copy),
           std::optional<Settings>(run.settings_copy), out_);
    while (true) {
        const AxisVec before = state_.pos.machine_mm;
        out_.clear();
        if (!run.next_pending_hole()) break;
        state_.pos = run.st.pos;
        state_.spindle = run.st.spindle;
        pass(out_, before);
    }
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
    // Cutter compensation finds its errors by look-ahead: staging it first lets a block it
    // rejects commit nothing (CrcStage::stage changes nothing when it throws).
    const bool through_crc = crc_.engaged() || st.crc.side != cutter::Side::Off;
    if (through_crc) crc_.stage(out, st.crc, machine_before);
    state_ = st;
    if (xf) xf_ = std::move(*xf);
    const bool settings_changed = settings && !(*settings == settings_);
    if (settings) settings_ = std::move(*settings);
    if (settings_changed && settings_listener_) settings_listener_(settings_);
    if (through_crc)
        crc_.emit_staged();
    else
        pass(out, machine_before);
}

void Executor::pass(std::vector<Canon>& out, const AxisVec& machine_before) {
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

void Executor::adopt_machine_position(const AxisVec& machine_mm, unsigned axes) {
    for (int a = 0; a < kMachineAxes; ++a)
        if ((axes >> a) & 1u) state_.pos.machine_mm[a] = machine_mm[a];
    AxisVec prog{};
    for (int a = 0; a < kMachineAxes; ++a) prog[a] = work_pos_mm(static_cast<Axis>(a));
    if (!xf_.identity()) {
        const Eigen::Vector3d p = xf_.inverse(Eigen::Vector3d(prog[0], prog[1], prog[2]));
        for (int a = 0; a < 3; ++a) prog[a] = p[a];
    }
    state_.pos.prog_mm = prog;
    state_.moved_since_sync = false;
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
