#pragma once
// Cutter radius compensation (G40/G41/G42) as a streaming core.
//
// The executor feeds, in program order, every block of one compensation plane as
// either a Move (a line or arc in the plane, or a line with no plane motion such
// as a Z-only move) or a Marker (a block with no motion: M code, dwell, comment,
// a canonical command that must keep its place in the stream). Coordinates are
// plane coordinates (a, b) after the executor's transforms (rotation, mirroring,
// scaling) and h along the plane normal:
//     G17: a=X b=Y h=Z    G18: a=Z b=X h=Y    G19: a=Y b=Z h=X
// so that "counter-clockwise" means G03 in every plane. Mirroring one plane axis
// swaps G41/G42 before the Move reaches this core; the radius is never scaled.
//
// The compensator holds back the last contour move until it has seen the next
// one (look-ahead), because the end of a compensated move depends on the corner
// it makes with the next move. Moves and Markers with no plane motion between two
// contour moves are held too (up to Config::lookahead_moves moves), and come out
// at the tool position of the corner, so Z moves and M codes do not break the
// compensation. Output entries carry the source tag of the block they belong to;
// corner pieces carry the tag of the block they lead into.
//
// Geometry (s = +1 for G41/left, −1 for G42/right, r = tool radius):
//   - a line is offset by s·r along its left normal; an arc keeps its centre and
//     its radius becomes ρ − s·r (CCW) or ρ + s·r (CW); a helix is offset in the
//     plane, its height follows the programmed move.
//   - start-up (first compensated move, a line): from the uncompensated tool
//     position to the point on the perpendicular of the next move at its start
//     (S0 §3.5.3 "offset to the perpendicular at the block start"); cancel
//     (a line with side Off): from the perpendicular at the end of the last move
//     (or, Config::cancel_at_inside_corner, the crossing with the cancel move's
//     offset when the cancel turns toward the tool) to the programmed end point.
//   - corners: inside (the turn is toward the tool side) → the two offset curves
//     are trimmed to their intersection; outside → an arc of radius r around the
//     programmed corner point, or (Config::extend_max_turn_deg) the two offset
//     tangents extended to their intersection for mild turns.
//   - a move too short for the tool at an inside corner (the offsets cross beyond its end) is
//     skipped: the moves around it are joined directly (their offsets' crossing, or a circle of
//     radius r about the corner point when the next corner turns away from the tool), accepted
//     only when the gouge check proves the path keeps r from the skipped move.
//   - errors (CompError: the block being pushed, the held block, for a gouge the contour move):
//     a 180° reversal, an inside corner whose offset curves do not meet within both moves
//     (gouge), an offset piece that comes closer than r to one of the last few contour moves at
//     the same height (gouge, Config::gouge_check_moves; sampled about every r/10), a tool
//     radius ≥ an inside arc radius, a plane change while active, start-up or cancel on an arc,
//     too many moves without plane motion. A push that throws leaves the compensator unusable:
//     callers that must survive an error push into a copy (see crc_stage.hpp).
//
// Not realtime: allocates, throws.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace interp::cutter {

namespace geom {
struct Segment;  // offset_geometry.hpp, internal
struct Curve;
}  // namespace geom

using Vec2 = Eigen::Vector2d;
/// The executor's identifier of a block, normally its source line; opaque here.
using SourceTag = std::int64_t;

enum class Side { Off, Left, Right };  // G40, G41, G42

/// A compensation error. The compensator finds most errors only when a later block shows the
/// corner (look-ahead), so two blocks are involved: `at_block`, the block being pushed when the
/// error was found (where it is reported), and `earlier_block`, the held block whose compensated
/// path cannot be made. A gouge also names the contour move the tool would cut (`contour_block`).
class CompError : public std::runtime_error {
  public:
    using Namer = std::function<std::string(SourceTag)>;

    CompError(std::string reason, SourceTag earlier, SourceTag at,
              std::optional<SourceTag> contour = std::nullopt, std::string tail = {});

    /// "<reason>[ <contour block><tail>] (with the move at <earlier block>)", blocks named by
    /// `name`; the suffix is left out when both blocks are the same.
    std::string message(const Namer& name) const;

    std::string reason;
    SourceTag earlier_block;
    SourceTag at_block;
    std::optional<SourceTag> contour_block;
    std::string tail;
};

enum class Shape { Line, Arc };

/// One programmed motion block, in plane coordinates.
struct Move {
    Shape shape = Shape::Line;
    Vec2 end{0, 0};
    Vec2 centre{0, 0};  // arcs
    bool ccw = false;   // arcs: G03 (after mirroring)
    double end_h = 0.0;
    bool rapid = false;
    Side side = Side::Off;   // G40/G41/G42 in effect for this block
    double radius_mm = 0.0;  // tool radius (from D); negative swaps G41/G42 (CRC-7)
    int plane = 17;          // G17/G18/G19; must not change while compensation is active
    SourceTag tag = 0;
};

/// A block with no motion that must keep its place in the output.
struct Marker {
    SourceTag tag = 0;
};

enum class Role {
    Plain,    // compensation off: the programmed move
    Startup,  // start-up move, or the link after a side/radius change
    Contour,  // the offset of a programmed move
    Corner,   // inserted around an outside corner
    Cancel,   // the move that leaves compensation
    Height,   // a move without plane motion (Z only), at the corner position
};

/// One output motion: a line or an arc (sweep_rad > 0; start == end only for a full circle).
struct OutMove {
    Shape shape = Shape::Line;
    Vec2 start{0, 0};
    Vec2 end{0, 0};
    Vec2 centre{0, 0};
    bool ccw = false;
    double sweep_rad = 0.0;
    double start_h = 0.0;
    double end_h = 0.0;
    bool rapid = false;
    Role role = Role::Plain;
    SourceTag tag = 0;
};
struct OutMarker {
    SourceTag tag = 0;
};
struct OutWarning {
    std::string text;
    SourceTag tag = 0;
};
using Output = std::variant<OutMove, OutMarker, OutWarning>;

enum class OnLookaheadExhausted {
    Error,          // raise a CompError naming both blocks
    Perpendicular,  // end the held move on its perpendicular and restart like a start-up
};

/// Where the last compensated move ends when the cancel move turns toward the tool side.
enum class CancelCorner {
    Perpendicular,  // on the perpendicular at its end, like the start-up (S0 §3.5.3 figures)
    Intersection,   // where its offset meets the cancel move's offset (ISO CRC-10, Fanuc)
};

struct Config {
    /// Moves without plane motion allowed between two contour moves.
    std::size_t lookahead_moves = 5;
    OnLookaheadExhausted on_exhausted = OnLookaheadExhausted::Error;
    /// Outside corners that turn by at most this angle use extended lines; 0 = always an arc.
    double extend_max_turn_deg = 0.0;
    CancelCorner cancel_at_inside_corner = CancelCorner::Perpendicular;
    /// Every offset piece is checked against this many preceding contour moves
    /// (and the next one): closer than the radius is a gouge error. 0 = off.
    std::size_t gouge_check_moves = 8;
};

class Compensator {
  public:
    explicit Compensator(Config config = {}, Vec2 start = Vec2::Zero(), double start_h = 0.0);
    ~Compensator();
    Compensator(Compensator&&) noexcept;
    Compensator& operator=(Compensator&&) noexcept;
    /// Copies are how a caller makes a block atomic: push into a copy, keep it only when no
    /// CompError was thrown. Assigning to an existing compensator reuses its storage.
    Compensator(const Compensator& other);
    Compensator& operator=(const Compensator& other);

    /// Tells the compensator where the tool is (after G92, G28, a program start).
    /// Only while compensation is off and nothing is held.
    void set_position(const Vec2& position, double h);

    void push(const Move& move);
    void push(const Marker& marker);

    /// End of program (or of the compensated section, e.g. before G28): flushes
    /// everything held; compensation still on is dropped with a warning.
    void finish();

    /// Takes the entries that are final.
    std::vector<Output> drain();

    /// True while a compensated move is held (compensation on).
    bool active() const { return pending_ != nullptr; }
    /// The held compensated move, while active.
    std::optional<SourceTag> held_move() const;

  private:
    struct Pending;  // the held contour move, defined in compensator.cpp
    using Held = std::variant<Move, Marker>;

    void push_no_plane_motion(const Move& move);
    void push_plain(const Move& move);
    void start_up(const Move& move);
    void finish_start_up(const Move& move);
    void join(const Move& move);
    void join_after_skip(const geom::Segment& seg, const geom::Curve& next, const Move& move);
    bool can_skip(const geom::Curve& next) const;
    void skip(const geom::Segment& seg, const Move& move);
    CompError corner_gouge(SourceTag earlier, SourceTag at) const;
    bool should_defer(const geom::Curve& next, double u_next) const;
    void emit_deferred();
    bool consumed_from_start(const geom::Segment& seg, const geom::Curve& next,
                             const Move& move) const;
    void link(const Move& move);
    void cancel(const Move& move);
    void end_pending_perpendicular();
    void flush_held();
    void emit_line(const Vec2& to, double to_h, bool rapid, Role role, SourceTag tag);
    void emit_piece(OutMove piece, bool rapid, Role role, SourceTag tag);
    void check_gouge(const OutMove& piece, double radius_mm) const;

    Config config_;
    Vec2 programmed_;  // uncompensated end of the last block
    double programmed_h_;
    Vec2 tool_;  // end of the last emitted output
    double tool_h_;
    std::optional<SourceTag> last_tag_;
    SourceTag current_tag_ = 0;  // the entry being pushed: where an error is reported
    std::unique_ptr<Pending> pending_;
    std::vector<Held> held_;
    std::size_t held_moves_ = 0;
    std::vector<Output> out_;
};

}  // namespace interp::cutter
