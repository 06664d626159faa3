#pragma once
// Internal to the back end: the code tables and one block's execution (BlockRun), shared by
// executor.cpp (tables, validation, coordinates, commit), block_setup.cpp (the modal, setting
// and machine-code steps) and block_motion.cpp (motion, canned cycles, program end).
#include <fmt/format.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "interp/executor.hpp"

namespace interp::back {

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
    PathMode,     // G61 / G64
    Flag,
};

struct GInfo {
    int code;
    GGroup group;
    bool uses_axes;  // the block's axis words belong to this code, not to a motion
};

const GInfo* find_g(int code);

enum class MGroup { Stop, Spindle, Coolant, Clamp, ToolChange, Own };

struct MInfo {
    int code;
    MGroup group;
};

const MInfo* find_m(int code);
std::string gname(int code);  // "G01", "G50.1", "G992"
std::string mname(int code);  // "M03", "M801"

inline constexpr char kAxisLetter[kMachineAxes] = {'X', 'Y', 'Z', 'A', 'B', 'C'};
inline constexpr char kCentreLetter[3] = {'I', 'J', 'K'};

inline Eigen::Vector3d xyz(const AxisVec& v) {
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
    bool has_pending_holes() const { return holes_ && holes_->holes_done() < holes_->hole_count(); }
    /// Appends the next hole of the block's canned cycle to the output; false when none is left.
    bool next_pending_hole();

    ExecState st;
    std::optional<ProgramTransform> xf_copy;
    std::optional<Settings> settings_copy;

  private:
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
    void step_path_mode();
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
        using C = std::decay_t<T>;
        if constexpr (std::is_same_v<C, canon::Sync>)
            st.moved_since_sync = false;
        else if constexpr (std::is_same_v<C, canon::Traverse> ||
                           std::is_same_v<C, canon::FeedLine> || std::is_same_v<C, canon::Arc> ||
                           std::is_same_v<C, canon::ConditionalMove>)
            st.moved_since_sync = st.moved = true;
        out_.push_back(Canon{b_.loc, CanonCommand(std::forward<T>(cmd))});
    }
    // emit() for an arc, returning the command to fill where it is stored: an Arc filled field by
    // field in a local and then copied whole stalled on store forwarding (a tenth of an arc
    // block's cycles). Call it after the block's last check (a rejected block's commands are
    // dropped, but a half-filled one should never be seen).
    canon::Arc& emit_arc() {
        st.moved_since_sync = st.moved = true;
        Canon& c = out_.emplace_back();
        c.loc = b_.loc;
        return c.cmd.emplace<canon::Arc>();
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
    // Program <-> machine coordinates; `offset` is offset_total(), which a block that converts
    // several points computes once.
    AxisVec to_machine(const AxisVec& prog, const AxisVec& offset) const;
    AxisVec prog_of_machine(const AxisVec& machine, const AxisVec& offset) const;
    AxisVec to_machine(const AxisVec& prog) const { return to_machine(prog, offset_total()); }
    AxisVec prog_of_machine(const AxisVec& machine) const {
        return prog_of_machine(machine, offset_total());
    }
    void resync_prog() { st.pos.prog_mm = prog_of_machine(st.pos.machine_mm); }
    void announce_offsets();
    void update_tool_offset(const SourceLoc& loc);
    AxisVec programmed_target() const;
    void require_no_scaling(int code) const;
    void require_no_mirror_coord_change() const;
    void require_feed(const char* what);
    std::optional<double> machine_setting(std::string_view name) const;
    void select_feed(const char* what);
    void select_rapid();

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
    cycles::CycleConfig cycle_config() const;
    void run_cycle();
    void run_hole_pattern();
    void begin_holes(cycles::BlockHoles&& b);
    void emit_cycle_steps(const std::vector<cycles::Step>& steps);
    double orient_angle_deg(const cycles::Vec3& tip_dir) const;

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
    // This block's canned-cycle holes, made lazily. Absent in most blocks: an empty HoleRun is a
    // few hundred bytes to zero for every block.
    std::optional<cycles::HoleRun> holes_;
    std::vector<cycles::Step> hole_steps_;  // one hole's steps
    SpindleDir cycle_dir_at_start_ = SpindleDir::Stop;
};

}  // namespace interp::back
