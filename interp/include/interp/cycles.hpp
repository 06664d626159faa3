#pragma once
// Canned drilling cycles (G73 G74 G76 G81–G89, G80, G98/G99) as a pure core.
//
// Contract: the executor owns the block, the modal groups and the coordinate
// transforms. For every block that programs a cycle code, or that runs while a
// cycle is active, it hands this core the block's words and a small context
// (distance mode, return mode, current position in program coordinates, spindle
// state) and receives a list of simple Steps, also in program coordinates, which
// it then transforms and emits as canonical commands tagged with the block's line.
// Nothing here knows about files, HAL, clocks or other interpreter state.
//
// Units: lengths mm, dwell in ms on input (P word) and seconds in Steps,
// feeds mm/min, spindle speed rpm.
//
// Errors are thrown as CycleError with a message without location; the executor
// prefixes file:line:col. A block that throws changes no cycle state.

#include <array>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace interp::cycles {

using Vec3 = std::array<double, 3>;  // X, Y, Z (indices 0, 1, 2), program coordinates

class CycleError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

enum class CycleCode { G73, G74, G76, G81, G82, G83, G84, G85, G86, G87, G88, G89 };

/// Maps a G number (73, 74, 76, 81…89) to its cycle; nullopt for anything else (G80 too).
std::optional<CycleCode> cycle_code_from_g(int g_number);
int g_number(CycleCode code);

// ---- Steps -----------------------------------------------------------------
struct Rapid {
    Vec3 to_mm;
};
struct Feed {
    Vec3 to_mm;
    double feed_mm_min;
    bool override_locked = false;  // tapping: feed override 100 %, feed hold waits (G74-2)
};
struct Dwell {
    double seconds;
};
struct SpindleStop {};     // M05 semantics
struct SpindleOrient {  // oriented spindle stop (M19 semantics)
    Vec3 tip_dir;  // unit vector, program X Y Z: where the cutter tip points, opposite to the
                   // shift that follows (FEATURES G76-2)
};
struct SpindleReverse {};  // reverse the running direction (tapping bottom and top)
struct SpindleRestart {};  // restart in the direction the spindle had when the cycle began
struct SpindleCw {};       // start clockwise (G87 before the cut)
struct SpindleSpeed {
    double rpm;  // tapping speed from the parameter, and back to the programmed S after
};
struct OperatorRetract {
};  // G88 manual mode: feed hold; the operator jogs out, cycle start resumes

using Step = std::variant<Rapid, Feed, Dwell, SpindleStop, SpindleOrient, SpindleReverse,
                          SpindleRestart, SpindleCw, SpindleSpeed, OperatorRetract>;

/// One-line printable form, e.g. "rapid X5 Y5 Z-5", used by golden tests.
std::string to_string(const Step& step);

// ---- Inputs ----------------------------------------------------------------
enum class Spindle { Stopped, Cw, Ccw };
enum class Plane { XY, ZX, YZ };  // G17, G18, G19
enum class OssTable { NcStudio, Iso };
enum class G88Retract { Feed, Manual };

/// Machine configuration the cycles read (named parameters in NcStudio).
struct CycleConfig {
    double retract_mm = 1.0;  // δ of G73/G83: #FIXEDCYCLE_BACK ("G73_G83 retract")
    int oss_direction = 0;    // #FIXEDCYCLE_OSS, see the tables in FEATURES G76-2
    OssTable oss_table = OssTable::NcStudio;
    std::optional<double> tap_spindle_rpm;  // "spindle speed when tapping"; nullopt keeps S
    G88Retract g88_retract = G88Retract::Feed;
    bool drill_axis_follows_plane = false;  // ISO: drill ⟂ plane; NcStudio: always Z
    // NcStudio V5.4 G76 (FEATURES G76-4): the bottom shift is U in X and V in Y, fed at the
    // "CYCP" speed (mm/min; 0 = the cycle's F), instead of Q in the OSS direction.
    bool g76_shift_uv = false;
    double g76_shift_feed_mm_min = 0.0;
    // NcStudio V5.4 G86 (FEATURES G86-1, C-45): the spindle restarts once back at R, before the
    // rapid to the initial level; the 6th edition restarts at the return level.
    bool g86_restart_at_r = false;
};

/// The cycle-relevant words of one block, as programmed (already in mm / ms).
/// axis_mm holds X, Y, Z words by index. K and L are the same count (the
/// executor maps L to k in the ncstudio dialect).
struct CycleWords {
    std::array<std::optional<double>, 3> axis_mm;
    std::optional<double> r_mm;
    std::optional<double> q_mm;
    std::optional<double> p_ms;
    std::optional<double> k;  // as written: checked to be a whole number in 0…kMaxRepeat
    std::optional<double> u_mm;  // V5.4 G76 shift in X (CycleConfig::g76_shift_uv only)
    std::optional<double> v_mm;  // V5.4 G76 shift in Y
};

/// The largest repeat count K (L) a block may ask for. The manuals give no limit; this one only
/// keeps the count in range of a long and a typo from running for days (REC, docs/interp-cycles.md).
inline constexpr long kMaxRepeat = 99'999'999;

/// State of the rest of the interpreter that a cycle block depends on.
struct BlockContext {
    bool incremental = false;  // G91 in effect for this block
    bool return_to_r = false;  // G99 in effect (after this block's own G98/G99)
    Vec3 position_mm{};        // tool position before the block, program coordinates
    double feed_mm_min = 0.0;  // modal F after this block's F word
    double spindle_rpm = 0.0;  // modal S
    Spindle spindle = Spindle::Stopped;
    Plane plane = Plane::XY;
    bool drill_axis_scaled = false;  // a scale factor ≠ 1 on the drilling axis (G51)
};

struct Expansion {
    std::vector<Step> steps;
    std::vector<std::string> warnings;
};

namespace detail {
/// Indices into Vec3 of the two positioning axes (a, b) and the drilling axis c.
struct AxisMap {
    int a;
    int b;
    int c;
};

/// Everything one hole needs, resolved to absolute levels on the drilling axis.
struct HoleSpec {
    CycleCode code;
    AxisMap axes;
    double pos_a_mm;
    double pos_b_mm;
    double r_mm;
    double z_mm;
    double initial_mm;
    bool return_to_r;
    double q_mm;
    double dwell_s;
    double feed_mm_min;
    double spindle_rpm;
    std::array<double, 2> shift_dir;  // unit vector in (a, b) for G76/G87
    std::optional<std::array<double, 2>> shift_uv_mm;  // V5.4 G76: signed shift in (a, b)
    double shift_feed_mm_min = 0.0;                    // and its feed
};
}  // namespace detail

/// Hole i (0-based) of a block's holes, as (a, b) positions in the positioning plane.
using HoleAt = std::function<std::array<double, 2>(long)>;

/// The holes one block drills, generated one hole at a time: a K1000000 repeat or a 9999×9999
/// G37 grid needs memory for a single hole's steps, not for the whole block. Built already
/// validated (every error of the block is thrown before it exists), so next() cannot fail.
class HoleRun {
  public:
    HoleRun() = default;  // drills nothing
    HoleRun(const detail::HoleSpec& spec, const BlockContext& ctx, const CycleConfig& cfg,
            long count, HoleAt at);

    long hole_count() const { return count_; }
    long holes_done() const { return next_; }
    /// Replaces `steps` with the next hole's steps (in order, starting where the previous hole
    /// left the tool); false once every hole has been produced.
    bool next(std::vector<Step>& steps);
    /// Appends every remaining hole to out (for small blocks and tests).
    void drain_into(Expansion& out);

  private:
    detail::HoleSpec spec_{};
    BlockContext ctx_{};
    CycleConfig cfg_{};
    long count_ = 0;
    long next_ = 0;
    HoleAt at_;
    Vec3 position_{};
};

/// One block's cycle work: its warnings (emit them first) and its holes.
struct BlockHoles {
    std::vector<std::string> warnings;
    HoleRun holes;
};

/// The modal cycle data, absolute levels on the drilling axis.
struct CycleData {
    std::optional<CycleCode> code;
    double initial_level_mm = 0.0;
    std::optional<double> r_level_mm;
    std::optional<double> z_level_mm;
    std::optional<double> q_mm;  // unsigned
    double dwell_ms = 0.0;
    std::array<double, 2> shift_uv_mm{};  // V5.4 G76 U, V (modal like Q)
};

/// #FC1…#FC14 and #FC50 for a library cycle O(600+n) (FEATURES FC-1/FC-2).
/// Index i holds #FCi; index 0 is unused.
using FcVariables = std::array<double, 51>;

class CycleState {
  public:
    const CycleData& data() const { return data_; }
    bool active() const { return data_.code.has_value(); }

    /// G80 or any group-01 code: forget the cycle code and Z R Q P. F stays
    /// with the executor (it survives cancel).
    void cancel() { data_ = CycleData{}; }

    /// A block with a cycle code (code set) or a block while a cycle is active
    /// (code empty). Updates the modal data and returns the holes the block drills
    /// (none for K0 or when the block has no X/Y/Z/R word), to be generated lazily.
    BlockHoles start_block(std::optional<CycleCode> code, const CycleWords& words,
                           const BlockContext& ctx, const CycleConfig& cfg);
    /// start_block with every hole expanded at once.
    Expansion run_block(std::optional<CycleCode> code, const CycleWords& words,
                        const BlockContext& ctx, const CycleConfig& cfg);

    /// Same data rules as run_block, for a cycle that public.dat redefines as
    /// O(600+n): returns the #FC variables instead of steps, or nullopt when the
    /// block drills nothing. #FC50 is left 0 (scratch for the subprogram).
    std::optional<FcVariables> run_custom_block(std::optional<CycleCode> code,
                                                const CycleWords& words, const BlockContext& ctx,
                                                const CycleConfig& cfg);

    /// G34–G37: drill the active cycle once at each of `count` holes (X, Y); moves
    /// between holes are rapids. The modal data is not changed.
    BlockHoles drill_pattern(long count, HoleAt hole_xy, const BlockContext& ctx,
                             const CycleConfig& cfg) const;
    /// drill_pattern over a list, expanded at once.
    Expansion drill_at(const std::vector<std::array<double, 2>>& holes_xy, const BlockContext& ctx,
                       const CycleConfig& cfg) const;

  private:
    struct Plan {
        bool drills = false;
        long repeat = 1;
    };
    Plan accept(std::optional<CycleCode> code, const CycleWords& words, const BlockContext& ctx,
                const CycleConfig& cfg);

    CycleData data_;
};

/// Canned cycles that public.dat redefines as O(600+n) (CC-19, FC-1/FC-2): the front end keeps
/// one of these and asks it, for every block outside the running library cycle, whether the
/// block runs the library cycle and with which #FC values. It keeps the custom cycle's modal
/// data by the built-in rules (Z R Q P retained, levels absolute under G91, #FC14 latched when
/// the cycle starts, a bare position re-runs the cycle until G80 or a group-01 code).
/// Everything is in program units: the #FC variables are what the subprogram computes with.
class CustomCycles {
  public:
    struct BlockInfo {
        std::optional<int> custom_g;  // a G n written in the block that public.dat redefines
        bool cancels = false;         // G80, G00–G03 or a built-in cycle code in the block
        CycleWords words;             // X Y Z R Q P K/L as written
        std::optional<double> f;      // F as written (#FC7; F is modal, CC-9)
        BlockContext ctx;  // G90/G91, G98/G99 after the block's own codes; position before it
    };
    struct Run {
        int g;           // run O(600+g)
        FcVariables fc;  // #FC1…#FC14 (#FC50 and the unused ones 0)
    };

    bool active() const { return g_.has_value(); }
    std::optional<int> active_g() const { return g_; }
    /// Updates the modal data; returns the run the block asks for, or nullopt (no custom cycle,
    /// K0, or no X/Y/Z/R word). Throws CycleError like the built-in cycles, and then changes
    /// nothing. The caller keeps a copy when something after this call may still reject the block.
    std::optional<Run> block(const BlockInfo& b);

  private:
    std::optional<Run> apply(const BlockInfo& b);

    std::optional<int> g_;
    CycleState data_;
    double feed_ = 0.0;
};

}  // namespace interp::cycles
