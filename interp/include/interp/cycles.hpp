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
struct SpindleOrient {};   // oriented spindle stop (M19 semantics)
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
};

/// The cycle-relevant words of one block, as programmed (already in mm / ms).
/// axis_mm holds X, Y, Z words by index. K and L are the same count (the
/// executor maps L to k in the ncstudio dialect).
struct CycleWords {
    std::array<std::optional<double>, 3> axis_mm;
    std::optional<double> r_mm;
    std::optional<double> q_mm;
    std::optional<double> p_ms;
    std::optional<long> k;
};

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

/// The modal cycle data, absolute levels on the drilling axis.
struct CycleData {
    std::optional<CycleCode> code;
    double initial_level_mm = 0.0;
    std::optional<double> r_level_mm;
    std::optional<double> z_level_mm;
    std::optional<double> q_mm;  // unsigned
    double dwell_ms = 0.0;
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
    /// (code empty). Updates the modal data and returns the steps of every hole
    /// the block drills (none for K0 or when the block has no X/Y/Z/R word).
    Expansion run_block(std::optional<CycleCode> code, const CycleWords& words,
                        const BlockContext& ctx, const CycleConfig& cfg);

    /// Same data rules as run_block, for a cycle that public.dat redefines as
    /// O(600+n): returns the #FC variables instead of steps, or nullopt when the
    /// block drills nothing. #FC50 is left 0 (scratch for the subprogram).
    std::optional<FcVariables> run_custom_block(std::optional<CycleCode> code,
                                                const CycleWords& words, const BlockContext& ctx,
                                                const CycleConfig& cfg);

    /// G34–G37: drill the active cycle once at each hole (X, Y); moves between
    /// holes are rapids. The modal data is not changed.
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

}  // namespace interp::cycles
