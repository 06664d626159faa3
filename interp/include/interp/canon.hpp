#pragma once
// The canonical command stream: what the interpreter's back end produces and what the motion
// planner, the `interp` HAL component and `cnc canon` consume. Every command is a plain value,
// tagged with the block it came from, in machine coordinates (mm for linear axes, degrees for
// rotary axes) and seconds. Each has a stable one-line text form (to_text) that golden tests
// compare, so changing a text form is a format change that needs every expected file updated.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>

#include "interp/block.hpp"

namespace interp {

using AxisVec = std::array<double, kMachineAxes>;

// Working plane; the pair (first, second) is right-handed about the normal axis, so a positive
// angle in (first, second) is counter-clockwise seen from the positive normal axis (G03).
enum class Plane { XY, ZX, YZ };

struct PlaneAxes {
    int first;
    int second;
    int normal;
};
constexpr PlaneAxes plane_axes(Plane p) {
    switch (p) {
        case Plane::ZX:
            return {2, 0, 1};
        case Plane::YZ:
            return {1, 2, 0};
        default:
            return {0, 1, 2};
    }
}

enum class SpindleDir { Stop, Cw, Ccw };

namespace canon {

// Per-block move modifiers (NcStudio G903, G905, G907, G908; G09 from ISO); all non-modal.
struct MoveFlags {
    bool force_full_override = false;    // G903: feed override fixed at 100 %
    bool force_programmed_feed = false;  // G905: programmed F beats the "default speed" setting
    bool rotary_shortest_path = false;   // G907
    bool rotary_degrees = false;         // G908
    bool exact_stop = false;             // G09: stop at the end of this move, whatever G64 says
    bool any() const {
        return force_full_override || force_programmed_feed || rotary_shortest_path ||
               rotary_degrees || exact_stop;
    }
};

struct Traverse {  // rapid straight move at the rapid rate
    AxisVec end_mm{};
    MoveFlags flags;
};
struct FeedLine {  // straight move at the feed rate
    AxisVec end_mm{};
    MoveFlags flags;
};
// Circular or helical move. The arc turns about `centre_mm` in `plane`; the normal axis and the
// rotary axes move linearly to `end_mm`. turns > 0 is counter-clockwise seen from the positive
// normal axis; |turns| - 1 extra full revolutions are made before the final partial sweep, and a
// partial sweep with end == start in the plane is a full circle (LinuxCNC's ARC_FEED rotation).
struct Arc {
    Plane plane = Plane::XY;
    AxisVec end_mm{};
    std::array<double, 3> centre_mm{};  // X Y Z; the normal-axis entry is the start's
    int turns = 1;
    MoveFlags flags;
};
struct SetFeedRate {
    double feed_mm_s = 0;
};
struct SetRapidRate {  // NcStudio: F in a G00 block; 0 = the machine's maximum
    double rapid_mm_s = 0;
};
// Path control mode (G61 / G64 [P]; PATH-9: an extension in NcStudio, which otherwise always
// blends with the machine's tolerance). Sent each time a program writes G61 or G64, and at
// program end when the mode was not the default. Applies to the moves that follow.
struct SetBlending {
    bool exact = false;       // G61: every move ends exactly at its end point (exact path)
    double tolerance_mm = 0;  // G64 P: allowed deviation at a blend; <= 0 = the machine default
};
struct SetFeedMode {  // only feed per minute exists in NcStudio; kept for the ISO dialect
    bool per_minute = true;
};
struct Dwell {
    double seconds = 0;
};
struct SetSpindleSpeed {
    double rpm = 0;
};
struct Spindle {  // M03 / M04 / M05
    SpindleDir dir = SpindleDir::Stop;
};
// Oriented spindle stop (inside G76/G87): the spindle stops with the cutter tip pointing at
// tip_angle_deg in the machine XY plane (counter-clockwise from +X), opposite to the shift
// that follows, so the tool clears the bore wall (FEATURES G76-2, #FIXEDCYCLE_OSS).
struct SpindleOrient {
    double tip_angle_deg = 0;
};
struct Coolant {  // M08 / M09
    bool flood = false;
};
struct SpindleClamp {  // M10 / M11 (V5.4)
    bool clamp = false;
};
struct ToolChange {  // T (NcStudio: T changes the tool) or M06
    int tool = 0;
};
struct SetToolNumber {  // M903: current tool number changes, nothing moves
    int tool = 0;
};
// The active tool offset vector (G43/G44/G49 or a tool change under G43). Informational: the
// move end points already include it.
struct ToolOffset {
    std::array<double, 3> offset_mm{};
};
// The active coordinate offsets, sent whenever one changes. Informational: move end points
// already include them. machine = work + wcs_origin + shift (tool offset aside).
struct Offsets {
    int wcs = 1;         // 1..6 = G54..G59
    AxisVec wcs_mm{};    // selected work origin including the common/external offset
    AxisVec shift_mm{};  // G92 shift plus the G992 temporary offset
};
struct SelectPlane {
    Plane plane = Plane::XY;
};
struct Units {  // G20/G21 (informational, the stream is always mm)
    bool inch = false;
};
struct SetOutput {  // M901
    int port = 0;
    bool plc_address = false;  // true: PLC[addr] form; false: port index (H form)
    bool level = false;
};
struct WaitInput {  // G906 PLC[a] LEVEL l P ms
    int port = 0;
    bool level = false;
    double timeout_s = 0;
};
struct Sync {};  // G906: wait until motion has finished and machine state is current
// At namespace scope, not nested in ConditionalMove: clang decides whether a nested class with
// default member initializers is default-constructible before it has read them, so
// std::optional<AxisWatch>::emplace() would not compile there.
struct ConditionalAxisWatch {
    int axis = 0;
    double speed_mm_s = 0;
    int port = 0;
    bool level = false;
    std::optional<double> max_travel_mm;
};
// G904: each listed axis moves at its signed speed until its input reaches the level or it has
// travelled max_travel_mm (no limit when absent).
struct ConditionalMove {
    using AxisWatch = ConditionalAxisWatch;
    std::array<std::optional<AxisWatch>, 3> axes;
    MoveFlags flags;
};
struct LatchConfig {  // G916: which input latches this axis's encoder, at which level
    int axis = 0;
    int port = 0;
    bool level = false;
};
struct LatchClear {};       // G918
struct LatchStopDistance {  // G919 H
    int axis = 0;
};
struct Message {  // M801
    std::string text;
};
struct IntMessage {  // M802
    std::int64_t code = 0;
};
struct HomeDone {  // M902 H: the current point becomes the machine origin position
    int axis = 0;
    double position_mm = 0;
};
struct Stop {  // M00, or M01 with the optional-stop switch on
    bool optional = false;
};
struct Warning {  // accepted, but the program probably does not mean it (M10 in 6th ed., …)
    std::string text;
};
struct ProgramEnd {
    bool rewind = false;  // M30
};

}  // namespace canon

using CanonCommand =
    std::variant<canon::Traverse, canon::FeedLine, canon::Arc, canon::SetFeedRate,
                 canon::SetRapidRate, canon::SetFeedMode, canon::Dwell, canon::SetSpindleSpeed,
                 canon::Spindle, canon::SpindleOrient, canon::Coolant, canon::SpindleClamp,
                 canon::ToolChange, canon::SetToolNumber, canon::ToolOffset, canon::Offsets,
                 canon::SelectPlane, canon::Units, canon::SetOutput, canon::WaitInput, canon::Sync,
                 canon::ConditionalMove, canon::LatchConfig, canon::LatchClear,
                 canon::LatchStopDistance, canon::Message, canon::IntMessage, canon::HomeDone,
                 canon::Stop, canon::Warning, canon::ProgramEnd, canon::SetBlending>;

// One command with the block it came from. loc.file is owned by the interpreter (see SourceLoc).
struct Canon {
    SourceLoc loc;
    CanonCommand cmd;
};

// Receives the stream in program order. Called on the interpreter's thread.
class CanonSink {
  public:
    virtual ~CanonSink() = default;
    virtual void emit(const Canon& c) = 0;
};

// The stable one-line native text form: "<line> <command> <arguments>", numbers with at most
// four decimals and no trailing zeros.
std::string to_text(const Canon& c);
std::string to_text(const CanonCommand& c);
// A number in the text form ("12.5", "-0.0001", "0").
std::string fmt_num(double v);
// Why a conditional move (G904) that ended without its inputs reaching their levels is an
// error (NCX-3: the alarm is the default), with where each watched axis stopped:
// "G904: Z stopped at -10 mm with input 3 not at level 1 (the maximum travel or a soft limit came
// first)".
std::string untripped_message(const canon::ConditionalMove& cm, const AxisVec& stop_mm);

}  // namespace interp
