// Non-realtime look-ahead planner: turns a stream of PathSegments into PreparedSegments.
//
// Flow of one move:
//   push(segment) -> geometry (line / arc element; a corner blend is inserted between two lines
//   when the tolerance allows, see geometry.hpp) -> per-element limits (limits.hpp) -> window.
//   When the window holds `window` elements, a backward pass (from a stop at the window's end)
//   and a forward pass (from the fixed speed where the last emitted record ended) give each
//   junction the highest speed that is both reachable and stoppable; the first half of the
//   window is then emitted as prepared records with their 1-D profiles. finish() emits the rest,
//   ending at rest. Because every plan ends in a stop at the window's end, anything emitted is
//   safe whatever arrives later; later segments can only raise the speeds still to be planned.
//
// Limit sharing: elements use (1 - reserve) of each axis's acceleration and jerk; the reserve is
// what the sampler needs to change the time scale (override, hold, abort) without exceeding the
// limits whatever the plan does. The sampler also changes the rate in the room each stretch of
// the plan leaves (sampler.hpp), with and without a jerk limit, so a small fixed reserve is
// kept (override_reserve, override_reserve_no_jerk: 1 % each; override_reserve_in_effect()
// tells which applies). Elements next to a junction that is not smooth (a tiny kink, or a
// curvature step under a jerk limit) also give up `junction_share`: such a junction is passed at
// a speed where the step is at most junction_share * limit over one servo period.
//
// Not thread-safe; one planner per motion queue. Throws PlanError on bad input; a rejected
// segment changes nothing.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <new>
#include <span>
#include <vector>

#include "motion/limits.hpp"
#include "motion/prepared.hpp"
#include "motion/types.hpp"

namespace motion {

struct OffsetFrame;  // planner.cpp: what an offset corner between two tangents asks of the axes

struct PlannerConfig {
    AxisLimits limits;
    double servo_period_s = 1e-3;
    double override_reserve = 0.01;  // share of acc/jerk kept for time scaling in the sampler
    double override_reserve_no_jerk = 0.01;  // the same when no axis has a jerk limit
    double junction_share = 0.1;    // share of acc/jerk a non-smooth junction may take
    double max_rate = 1.2;          // highest feed override the sampler will apply
    std::size_t window = 4096;      // look-ahead length in elements
};

// Throws std::invalid_argument naming the bad field.
void validate(const PlannerConfig& cfg);

// The reserve the planner keeps and the sampler relies on: override_reserve when any axis has a
// jerk limit, else override_reserve_no_jerk.
double override_reserve_in_effect(const PlannerConfig& cfg) noexcept;

class Planner {
  public:
    Planner(const PlannerConfig& cfg, const AxisArray& start_mm);

    void push(const PathSegment& seg);
    // End of the program (or a point where the machine must come to rest): plans and emits
    // everything, the last record ending at rest with program_end set.
    void finish();
    // Forget everything (after an abort) and start again from start_mm.
    void reset(const AxisArray& start_mm);

    std::size_t ready() const noexcept { return out_.size() - out_head_; }
    // The next ready record by reference (nullptr when none is ready), for a consumer that
    // would copy it anyway: pop() copies all ~950 bytes of it once more. The record stays
    // valid until the next push(), finish() or reset().
    const PreparedSegment* pop_ref() noexcept {
        return out_head_ == out_.size() ? nullptr : &out_[out_head_++].rec();
    }
    bool pop(PreparedSegment& out) noexcept;
    // Copies up to out.size() ready records; returns how many.
    std::size_t take(std::span<PreparedSegment> out) noexcept;

    const AxisArray& end_position() const noexcept { return last_end_; }
    const PlannerConfig& config() const noexcept { return cfg_; }

  private:
    struct Piece {
        Element geom;
        double feed_mm_s;  // rapids: the rapid rate cap, 0 = none
        bool rapid = false;
        double tolerance_mm;
        bool exact_stop;
        std::int32_t line;
        std::uint32_t move_id;
        double trim_start_mm = 0;
        bool rough_start = false;  // the junction at its start is not smooth
        bool start_at_rest = false;  // the tool is at rest where it starts (program start, a stop)
    };
    // Where emit() builds a record. Its bytes are not cleared when the slot is made: an
    // emplace_back() of a PreparedSegment cleared all ~950 of them (GCC: rep stos, also for a
    // record constructed with its members given), 19 % of emit_group()'s time, before most
    // were written again. emit() writes every member of the record (a PreparedSegment, which
    // as an aggregate is created in the bytes implicitly).
    struct RecordSlot {
        RecordSlot() noexcept {}
        PreparedSegment& rec() noexcept {
            return *std::launder(reinterpret_cast<PreparedSegment*>(bytes));
        }
        alignas(PreparedSegment) std::byte bytes[sizeof(PreparedSegment)];
    };
    struct Item {
        // Built in place in items_ from its element: value-initialising it first would clear
        // all of it only for add_item() to overwrite it; bounds() writes straight into it.
        // moving: the only axes e moves in, if known (bounds(e, moving)).
        Item(const Element& e, std::span<const int> moving)
            : geom(element_copy(e)),
              bounds(moving.empty() ? motion::bounds(e) : motion::bounds(e, moving)) {}
        // With its bounds already known (item_bounds(e, moving) made them).
        Item(const Element& e, const ElementBounds& b)
            : geom(element_copy(e)), bounds(bounds_copy(b)) {}
        // With the element make() returns built in place (no copy), and bounds(geom).
        struct Made {};
        template <class MakeElement>
        Item(Made, MakeElement&& make) : geom(make()), bounds(motion::bounds(geom)) {}
        Element geom;
        ElementBounds bounds;  // bounds(geom), kept for the rate caps when it is emitted
        ElementLimits lim;
        double end_cap_mm_s;  // junction speed limit at its end
        bool rough;           // next to a junction that is not smooth
        bool rapid;
        std::int32_t line;
        std::uint32_t move_id;
    };
    // Consecutive elements planned as one profile (jerk-limited mode; otherwise one each).
    struct Group {
        std::size_t first, end;  // item indices [first, end)
        double length_mm;
        double vcap_mm_s;
        double end_cap_mm_s;
        TangentLimits tangent;
    };
    enum class Blend : std::uint8_t { None, Quartic, Parabola, Curve, Offset };
    // What classify() decides for the junction after a piece. Filled in place in junction_ (the
    // elements make it about 1.3 kB): only the members the blend kind names are set.
    struct Junction {
        double cap_mm_s;    // speed limit where the first piece ends (at the blend if any)
        bool rough;         // that junction is not smooth
        double blend_l_mm;  // > 0: insert a blend cutting this much from both sides
        Blend blend;
        Element curve;                  // Curve: the Bezier blend; Offset: the parabola
        double curve_end_cap_mm_s = 0;  // Curve: speed limit where the Bezier blend ends
        bool curve_end_rough = false;   // that junction is not smooth
        // Blend::Offset (no jerk limit): shift out, turn (curve: the parabola between two
        // lines), shift back; the first move loses blend_l_mm, the second cut_after_mm.
        Element shift_out, shift_back;
        double cut_after_mm = 0;
        // Curve and Offset: the only axes their pieces move in (the first piece_axis_count),
        // when they were built on a corner path at rest (make_corner_bezier: every control point
        // equals the corner's in the others), else none; see bounds(e, moving).
        std::array<int, kAxes> piece_axes;
        int piece_axis_count = 0;
        bool has_shift_out = true, has_shift_back = true;  // one-sided: only one of them
        // One-sided: its one shift's Item bounds and limits, as add_item() would make them
        // (one_sided_offset_corner needs them for its estimate first).
        ElementBounds shift_bounds;
        ElementLimits shift_lim;

        void set(double cap, bool is_rough, double l_mm, Blend kind = Blend::None) {
            cap_mm_s = cap, rough = is_rough, blend_l_mm = l_mm, blend = kind;
            piece_axis_count = 0;
        }
        // After set(): the pieces were built by make_corner_bezier() on `path`.
        void set_piece_axes(const CornerPath& path) {
            if (!path.still_at_rest) return;
            std::copy_n(path.axes.begin(), path.dims, piece_axes.begin());
            piece_axis_count = path.dims;
        }
        std::span<const int> moving_axes() const {
            return {piece_axes.data(), static_cast<std::size_t>(piece_axis_count)};
        }
    };

    void classify(const Piece& p, const Piece& next, Junction& jn) const;
    // A Bezier blend for a corner with an arc (or any corner without a jerk limit) written into
    // jn, or false (jn's blend members left undefined) when no blend within the tolerance fits.
    // l_speed_mm: the longest cut worth making (see classify).
    bool bezier_corner(const Piece& p, const Piece& next, double sin_angle, double feed_mm_s,
                       double l_speed_mm, Junction& jn) const;
    // The corner of two lines cut on lines moved outwards (offset_corner, else
    // one_sided_offset_corner) written into jn, or false (as above) when neither fits.
    bool offset_corners(const Piece& p, const Piece& next, double sin_angle, double l_speed_mm,
                        Junction& jn) const;
    // The corner of two lines cut on lines moved outwards (see planner.cpp) written into jn, or
    // false (as above) when that does not fit; f: offset_frame() of the lines' tangents.
    bool offset_corner(const Piece& p, const Piece& next, const OffsetFrame& f, double sin_angle,
                       double l_speed_mm, Junction& jn) const;
    // The same with only one line moved outwards, for a corner where the other line has no
    // room for a shift (see planner.cpp), or false when that does not fit.
    bool one_sided_offset_corner(const Piece& p, const Piece& next, const OffsetFrame& f,
                                 double sin_angle, double l_speed_mm, Junction& jn) const;
    // The same for a corner where one or both moves are arcs or helices (the moves carried
    // outwards with their curvature, see planner.cpp), or false when that does not fit.
    bool offset_arc_corner(const Piece& p, const Piece& next, double sin_angle, double l_speed_mm,
                           Junction& jn) const;
    // Highest speed at which a step between these second derivatives stays within the
    // junction share of one period's jerk (infinite without a jerk limit).
    double curvature_step_cap(const AxisArray& d2_before, const AxisArray& d2_after) const;
    void close_piece(Piece& p, Piece* next);
    // blend_centripetal: LimitShares::blend_centripetal for a corner blend (0 = default).
    // moving: as for Item.
    void add_item(const Element& e, double feed, double end_cap, bool rough, const Piece& owner,
                  bool rapid, double blend_centripetal = 0, std::span<const int> moving = {});
    // add_item(make(), feed, end_cap, rough, owner, rapid) with the element built in place in
    // its Item (a trimmed move: a 400-byte copy less), only if it is longer than kMinLength_mm
    // (planner.cpp); returns its length either way.
    template <class MakeElement>
    double add_item_made(MakeElement&& make, double feed, double end_cap, bool rough,
                         const Piece& owner, bool rapid);
    // The rest of an Item once its element and bounds are in place.
    void set_item_limits(Item& it, double feed, double end_cap, bool rough, const Piece& owner,
                         bool rapid, double blend_centripetal);
    // add_item(e, feed, kInf, false, owner, rapid, ...) for an element whose bounds and limits
    // were already made as add_item() makes them (item_bounds(), then element_limits() with
    // the shares 1 - reserve_).
    void add_item_with_limits(const Element& e, const ElementBounds& b, const ElementLimits& lim,
                              const Piece& owner, bool rapid);
    std::size_t plan_and_emit(bool all);  // returns how many records it emitted
    bool can_join(const Group& g, const Item& it) const;
    void build_groups();
    void compact();
    // End speed of group g entered at v: as high as reachable, at most `bound`.
    double forward_speed(const Group& g, double v, double bound) const;
    void emit_group(const Group& g, double v_in, double v_out);
    // make_profile(Profile1D&) writes the record's profile into the default one it is given.
    template <class MakeProfile>
    void emit(const Item& it, MakeProfile&& make_profile);

    PlannerConfig cfg_;
    AxisArray last_end_;
    bool have_pending_ = false;
    // The piece waiting for its successor (pieces_[pending_]) and the one being pushed, in
    // turns: a new piece is built in the free slot instead of being copied in.
    std::array<Piece, 2> pieces_{};
    int pending_ = 0;
    std::vector<Item> items_;
    std::size_t head_ = 0;
    double v_start_ = 0;
    std::vector<Group> groups_;
    std::size_t group_head_ = 0;   // first group not yet emitted
    std::size_t grouped_end_ = 0;  // items before this index belong to a group
    std::vector<double> vj_;
    std::vector<RecordSlot> out_;
    std::size_t out_head_ = 0;
    std::uint32_t seq_ = 0;
    Junction junction_{};  // close_piece's, reused: clearing 1.3 kB per junction cost more
    bool jerk_mode_ = false;
    double reserve_ = 0;  // override_reserve_in_effect(cfg_)
};

}  // namespace motion
