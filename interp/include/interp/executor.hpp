#pragma once
// The back end: executes evaluated blocks (block.hpp) against the modal state, the coordinate
// transforms and the persistent settings, and emits canonical commands (canon.hpp). It also
// answers the front end's machine queries from its own model (standalone / check mode).
//
// A block is executed on a copy of the state; only when every step succeeded is the copy
// committed and the block's canonical commands passed to the sink. So a rejected block changes
// nothing and emits nothing (STYLE: parse, validate, then commit).
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "interp/block.hpp"
#include "interp/canon.hpp"
#include "interp/crc_stage.hpp"
#include "interp/cycles.hpp"
#include "interp/modal.hpp"
#include "interp/persist.hpp"
#include "interp/transform.hpp"

namespace interp {

// Dialect switches of the back end (FEATURES `cfg:` names in comments).
struct BackendConfig {
    bool v54_compat = false;         // cfg:ncstudio_v54_compat
    bool ijk_incremental = true;     // cfg:ncstudio_ijk_incremental
    bool g00_z_split = true;         // cfg:ncstudio_g00_z_split
    double arc_tolerance_mm = 0.01;  // cfg:arc_tolerance
    bool optional_stop = false;      // the operator's M01 switch
    bool t_changes_tool = true;      // cfg:t_changes_tool (NcStudio 6th: T changes the tool)
    bool end_stops_spindle = true;   // AUTOSTOPSPINDLE: M02/M30 stop spindle and coolant
    double max_rapid_mm_s = 0;       // clamp for F in G00 blocks; 0 = no clamp
    double max_feed_mm_s = 0;        // FEED-8: cutting feeds are clamped to this; 0 = no clamp
    // MIR-5 (ISO): G28, G53, G54–G59, G92, G921, G922 and G992 are refused while an axis is
    // mirrored. NcStudio's manual has no such rule, so it is off for the ncstudio dialects.
    bool mirror_forbids_coord_changes = false;
    // The machine's default cutting feed, used by a feed move when no F was ever programmed
    // (NcStudio always has one; the manual's examples rely on it). 0 = such a move is an error.
    double default_feed_mm_s = 0;
    // G00-4, cfg:ncstudio_use_default_speed (S0 §3.10 G905, "使用缺省速度"): feed moves run at
    // default_feed_mm_s and rapids at the machine's rapid speed whatever F the program writes;
    // only a G905 block runs at the programmed F. Needs default_feed_mm_s > 0.
    bool use_default_speed = false;
    AxisVec reference_mm{};        // G28 reference point, machine coordinates
    AxisVec home_position_mm{};    // M902: machine origin position parameter per axis
    std::uint64_t input_bits = 0;  // standalone model of the input ports
    // Standalone model of G904: the machine coordinate (X, Y, Z) at which the watched input
    // changes. Without one, the input is taken to change at once and the axis does not move.
    std::array<std::optional<double>, 3> g904_trip_mm{};
    // Machine settings readable as named parameters (SAFEHEIGHT, MOBICALI_THICKNESS, …), mm.
    std::map<std::string, double, std::less<>> machine_settings;
    cycles::CycleConfig cycles;  // canned-cycle machine parameters (FIXEDCYCLE_BACK, …)
    cutter::Config cutter;       // cutter radius compensation look-ahead and corner rules
};

// Everything the executor keeps between blocks apart from settings and transforms.
struct ExecState {
    MotionModal motion;
    PathModal path;
    UnitsModal units;
    FeedModal feed;
    SpindleModal spindle;
    CoolantModal coolant;
    ToolModal tool;
    CoordModal coord;
    Position pos;
    IoState io;
    cycles::CycleState cycle;        // active canned cycle and its modal data (G80 = none)
    bool cycle_return_to_r = false;  // G99 (else G98)
    bool feed_clamp_warned = false;  // FEED-8: warn once per program
    cutter::Side crc_side = cutter::Side::Off;  // G40/G41/G42 as programmed
    std::optional<int> crc_d;                   // last D word (selects the radius)
    CrcBlockState crc;     // what the compensator gets for this block (mirroring swaps the side)
    bool started = false;  // the initial offsets have been announced
    // A move was emitted after the last Sync: reading the current point needs a sync first.
    bool moved_since_sync = false;
    bool moved = false;  // a move was emitted in this program (C-37: units belong before it)
};

class Executor final : public BlockExecutor, public MachineQuery {
  public:
    Executor(CanonSink& sink, BackendConfig cfg, Settings settings = {});

    void execute(const Block& block) override;
    void end_of_input(const SourceLoc& loc) override;

    // MachineQuery, answered from the executor's own model.
    double machine_pos_mm(Axis axis) override;
    double work_pos_mm(Axis axis) override;
    std::uint64_t input_bits() override { return cfg_.input_bits; }
    std::uint64_t output_bits() override { return state_.io.outputs; }
    double spindle_rpm() override;
    double mm_per_program_unit() override { return state_.units.mm_per_unit; }
    bool incremental_mode() override { return state_.motion.incremental; }
    bool cycle_return_to_r() override { return state_.cycle_return_to_r; }
    std::optional<double> setting(std::string_view name) override;
    bool can_write_setting(std::string_view) override { return true; }
    void write_setting(std::string_view name, double value) override {
        set_persistent_param(name, value);
    }

    // Called after every committed block that changed a persistent setting (for saving).
    void on_settings_changed(std::function<void(const Settings&)> fn) {
        settings_listener_ = std::move(fn);
    }
    // A persistent named parameter written by the program (front end).
    void set_persistent_param(std::string_view name, double value);
    // The machine stopped where the program could not know beforehand (a conditional move,
    // G904): on the axes in `axes` (bit a = axis a) the current point becomes machine_mm, and
    // the program position follows through the active offsets and transforms.
    void adopt_machine_position(const AxisVec& machine_mm, unsigned axes);

    const Settings& settings() const { return settings_; }
    const ExecState& state() const { return state_; }
    const ProgramTransform& transform() const { return xf_; }
    const BackendConfig& config() const { return cfg_; }

  private:
    void commit(ExecState&& st, std::optional<ProgramTransform>&& xf,
                std::optional<Settings>&& settings, std::vector<Canon>& out);
    // The block's commands to the sink, through cutter compensation while it is engaged.
    void pass(std::vector<Canon>& out, const AxisVec& machine_before);

    CanonSink& sink_;
    BackendConfig cfg_;
    Settings settings_;
    ExecState state_;
    ProgramTransform xf_;
    std::vector<Canon> out_;  // the current block's commands, reused to avoid allocation
    CrcStage crc_;
    std::function<void(const Settings&)> settings_listener_;
};

}  // namespace interp
