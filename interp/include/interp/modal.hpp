#pragma once
// Modal state of the back end as a few small structs, each owned by the executor and passed
// explicitly to the handlers that need it. Lengths are stored in mm whatever G20/G21 says.
#include <cstdint>
#include <optional>

#include "interp/canon.hpp"

namespace interp {

enum class Motion { Rapid, Linear, ArcCw, ArcCcw };
enum class ToolLengthMode { Off, Plus, Minus };  // G49 / G43 / G44

struct MotionModal {
    Motion motion = Motion::Rapid;  // FEATURES G00-1: NcStudio default REC G00
    Plane plane = Plane::XY;
    bool incremental = false;  // G91
};

// G61 / G64 P (PATH-9). The default is NcStudio's: continuous with the machine's tolerance.
struct PathModal {
    bool exact = false;
    double tolerance_mm = 0;  // <= 0: the machine default
    bool operator==(const PathModal&) const = default;
};

struct UnitsModal {
    double mm_per_unit = 1.0;  // 25.4 under G20/G70
    bool inch() const { return mm_per_unit != 1.0; }
};

// NcStudio keeps two feed registers (FEATURES G00-3): F in a G00 block sets the rapid speed only.
struct FeedRegisters {
    double feed_mm_s = 0;
    bool feed_set = false;
    double rapid_mm_s = 0;  // 0 = the machine's rapid ("idle travel") speed
};

// The rates the stream has announced, which the moves run at. Normally they are the program's F
// registers; with the machine's "use default speed" parameter on (G00-4) they are the machine's
// defaults, and the program's F words only fill `programmed`, which a G905 block runs at.
struct FeedModal : FeedRegisters {
    FeedRegisters programmed;
};

struct SpindleModal {
    SpindleDir dir = SpindleDir::Stop;
    double rpm = 0;  // kept while stopped (M03-1)
};

struct CoolantModal {
    bool flood = false;
    bool clamped = false;  // M10/M11 (V5.4)
};

struct ToolModal {
    int current = 0;
    ToolLengthMode length_mode = ToolLengthMode::Off;
    std::optional<int> h_register;      // H of the G43/G44 block; none = current tool (TLC-7 REC)
    std::array<double, 3> offset_mm{};  // the active tool offset vector
};

// Work-system selection and the non-persistent G992 offset (restored at program end).
struct CoordModal {
    int wcs = 0;  // 0..5 = G54..G59
    AxisVec g992_mm{};
    bool g992_active = false;
};

// The last programmed point in program coordinates (mm, before the programmed transforms) and
// where the machine is. They differ by the transforms and offsets.
struct Position {
    AxisVec prog_mm{};
    AxisVec machine_mm{};
};

struct IoState {
    std::uint64_t outputs = 0;  // bit n = output port n
};

}  // namespace interp
