// Path elements the planner strings together: straight lines, circular arcs/helices, and the
// corner blends it inserts between lines. Each element is a curve p(s) over s in [0, length_mm];
// for lines and arcs s is the arc length, for blends it is a pseudo length with |p'(s)| <= 1, so
// the path speed never exceeds ds/dt.
//
// Corner blend (G64 P): a quartic curve from the point `l` before the corner to the point `l`
// after it whose tangent turns from T1 to T2 as sigma(u) = 3u^2 - 2u^3, u = s / 2l:
//
//        T1             corner
//   ----------->--------+            p'(s)   = T1 + sigma(u) (T2 - T1)
//                 \_    |            p''(s)  = sigma'(u) (T2 - T1) / 2l    (zero at both ends)
//                   \   | T2         p'''(s) = sigma''(u) (T2 - T1) / 4l^2
//                    \  v
// Curvature is zero at both ends, so a blend joins its lines without an acceleration step, and
// the largest distance from the programmed corner lines is (3/16) l sin(angle).
//
// Bezier blend: a cubic Bezier curve B(u), u = s / length, from control points P0 (origin), P1
// (a), P2 (b), P3 (end). length is the largest norm of the hodograph's control points
// 3 (P[i+1] - P[i]), so |p'(s)| <= 1 as for the other elements. Used where the corner need not
// join without an acceleration step (no jerk limit: the time-optimal parabolic corner, which is
// a cubic with P1 = P0 + 2/3 (C - P0), P2 = P3 + 2/3 (C - P3)), and for corners with arcs.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "motion/types.hpp"

namespace motion {

enum class ElementKind : std::uint8_t { Line, Arc, Blend, Bezier };

// Trivially copyable: it travels inside PreparedSegment through the realtime ring.
struct Element {
    ElementKind kind = ElementKind::Line;
    double length_mm = 0;
    AxisArray origin{};  // line: start; arc: centre with the start's off-plane values; blend: start
                         // bezier: P0
    AxisArray a{};       // line: unit direction; arc: in-plane unit u; blend: T1; bezier: P1
    AxisArray b{};       // arc: in-plane unit w (u x w = normal); blend: T2 - T1; bezier: P2
    AxisArray c{};       // arc: linear displacement of the off-plane axes over the whole arc
    AxisArray end{};     // exact programmed end, returned at s = length
    double radius_mm = 0;
    double theta0_rad = 0;
    double sweep_rad = 0;  // signed, positive counter-clockwise from u towards w
};

// A copy of e, or e assigned to `to`, member by member: GCC copies the whole 400-byte struct
// with rep movs, whose start-up costs more than the copy; member by member it uses vector
// moves. For the planner, which copies every element it plans twice (into its window, then
// into the record it emits): 3 % of the planning time on line programs (docs/benchmarks.md).
static_assert(sizeof(Element) == 8 + 8 + 5 * sizeof(AxisArray) + 3 * 8,
              "element_copy and assign_element copy every member of Element: add new ones there");
inline Element element_copy(const Element& e) noexcept {
    return Element{e.kind, e.length_mm, e.origin, e.a,         e.b,
                   e.c,    e.end,       e.radius_mm, e.theta0_rad, e.sweep_rad};
}
inline void assign_element(Element& to, const Element& e) noexcept {
    to.kind = e.kind;
    to.length_mm = e.length_mm;
    to.origin = e.origin;
    to.a = e.a;
    to.b = e.b;
    to.c = e.c;
    to.end = e.end;
    to.radius_mm = e.radius_mm;
    to.theta0_rad = e.theta0_rad;
    to.sweep_rad = e.sweep_rad;
}

// Position and its first three derivatives with respect to s. evaluate() sets every member
// (none is cleared first: the planner evaluates several points per corner).
struct CurvePoint {
    AxisArray p, d1, d2, d3;
};

// Realtime-safe: noexcept, no allocation, constant time.
void evaluate(const Element& e, double s_mm, CurvePoint& out) noexcept;
// The same values as evaluate() for what they set: p and the derivatives up to `order` (0-3;
// the others are left as they were), or the position only. For the planner, which needs no
// more at most of its points.
void evaluate_upto(const Element& e, double s_mm, int order, CurvePoint& out) noexcept;
AxisArray point_at(const Element& e, double s_mm) noexcept;

// Per-axis bounds over the whole element: |p'_k| <= g1[k], |p''_k| <= g2[k], |p'''_k| <= g3[k].
// For arcs, `tangential_in_plane[k]` and `linear[k]` split g1 so that the planner can use the
// exact (rotating-vector) combination of tangential and centripetal acceleration.
// bounds() sets every member (none is cleared first: it runs twice per planned element).
// `axes` lists, in increasing order, the first `axis_count` axes the element may move: every
// bound of any other axis is 0, so a loop over the axes that skips zero bounds can run over
// these only (most programs move 2 or 3 of the 9 axes).
struct ElementBounds {
    AxisArray g1, g2, g3;
    AxisArray tangential_in_plane, linear;
    std::array<std::uint8_t, kAxes> axes;
    int axis_count;
};
ElementBounds bounds(const Element& e) noexcept;
// bounds(e), the same values, for a Bezier whose four control points are equal, and finite, in
// every axis but the `moving` ones (increasing), as make_corner_bezier()'s are in the still axes
// of a path at rest (CornerPath::still_at_rest): each bound there is a finite factor times the
// magnitude of a difference of equal numbers, +0, so only the moving axes are computed. Any
// other element, and a Bezier whose factors (powers of 1 / length) are not finite, get
// bounds(e). For the planner, whose corner pieces move in 2 or 3 of the 9 axes.
ElementBounds bounds(const Element& e, std::span<const int> moving) noexcept;
// The same written into `out`, for a caller that keeps the bounds in a larger object: assigning
// the value bounds() returns copies its 376 bytes once more (GCC: rep movs, whose start-up costs
// more than the copy).
void bounds_into(const Element& e, std::span<const int> moving, ElementBounds& out) noexcept;
// A copy of b, member by member (as element_copy, for the same reason).
static_assert(sizeof(ElementBounds) == 5 * sizeof(AxisArray) + 16,
              "bounds_copy copies every member of ElementBounds: add new ones there");
inline ElementBounds bounds_copy(const ElementBounds& b) noexcept {
    return ElementBounds{b.g1, b.g2, b.g3, b.tangential_in_plane, b.linear, b.axes, b.axis_count};
}

Element make_line(const AxisArray& start, const AxisArray& end) noexcept;
// Throws PlanError for a zero radius, an end off the circle, a bad plane or zero turns.
Element make_arc(const AxisArray& start, const PathSegment& seg);
// t1, t2 unit tangents at the corner, `l` the distance cut from each side.
Element make_blend(const AxisArray& corner, const AxisArray& t1, const AxisArray& t2,
                   double l_mm) noexcept;

// Unit tangent and second derivative at the element's start (s = 0) and end (s = length).
struct EndDerivs {
    AxisArray tangent{}, d2{};
};
// with_d2 false: d2 is left 0 (not needed, not computed).
EndDerivs start_derivs(const Element& e, bool with_d2 = true) noexcept;
EndDerivs end_derivs(const Element& e, bool with_d2 = true) noexcept;

// Cubic Bezier blend through control points p0..p3 (see above). Its pseudo length is positive
// unless all four points coincide.
Element make_bezier(const AxisArray& p0, const AxisArray& p1, const AxisArray& p2,
                    const AxisArray& p3) noexcept;

// The parabolic corner between two lines: from `l` before the corner (unit tangent t1) to `l`
// after it (t2), control points 2/3 of the way to the corner. p'' = (t2 - t1) / 2l throughout,
// and its largest distance from the lines is (l / 4) sin(angle).
Element make_parabola(const AxisArray& corner, const AxisArray& t1, const AxisArray& t2,
                      double l_mm) noexcept;

// The arc element trimmed to [from_mm, length - to_mm] of the original (same circle, helix
// pitch and direction).
// end_mm: the arc's point at length - to_mm (point_at) if the caller has it already.
Element trim_arc(const Element& arc, double from_mm, double to_mm,
                 const AxisArray* end_mm = nullptr) noexcept;

// The line element trimmed to [from_mm, length - to_mm] of the original.
Element trim_line(const Element& line, double from_mm, double to_mm) noexcept;

// Control points of a cubic Bezier (make_bezier builds the element).
struct BezierPoints {
    AxisArray p0, p1, p2, p3;
};

// Corner blend for corners with an arc: a Bezier from p0 (unit tangent t1 there) to p3 (unit
// tangent t2), its inner control points h along the tangents with h = 2/3 l (the parabola's, l
// being the cut from each move), or the smallest larger h for which |p'| = 1 at both ends and
// <= 1 inside (|p3 - p0 - h (t1 + t2)| <= h). None if no h fits.
std::optional<BezierPoints> corner_bezier_points(const AxisArray& p0, const AxisArray& t1,
                                                 const AxisArray& p3, const AxisArray& t2,
                                                 double l_mm) noexcept;

// The programmed path near a corner, for proving a blend's distance from it: the last
// `before_mm` of `before` and the first `after_mm` of `after` (which starts where `before`
// ends) as chords, each with `slack_mm`, how far the path between its ends may lie from it (0
// for a line; for an arc or helix R dphi^2 / 8, the bound of linear interpolation's error by
// max |p''| / 8). Arcs get enough chords (at most kMaxChordsPerMove) for a slack below 2 % of
// the distance to be proved. Only the axes either move changes are kept (`axes`); in the
// others the path stays at `fixed`.
struct CornerPath {
    static constexpr int kMaxChordsPerMove = 8;
    static constexpr int kMaxChords = 2 * kMaxChordsPerMove;
    std::array<int, kAxes> axes{};
    int dims = 0;
    std::array<bool, kAxes> moving{};
    AxisArray fixed{};
    std::array<int, kAxes> still_axes{};  // the others, in increasing order
    int still_count = 0;
    // Both moves are lines or arcs that stay at `fixed` in the still axes: every point and
    // tangent evaluate() gives of them equals fixed there and 0 (see corner_bezier_within).
    bool still_at_rest = false;
    // Only the first `count` chords are set (left uninitialised: this is built for every
    // corner with an arc, and clearing 2 kB cost as much as the proof).
    std::array<AxisArray, kMaxChords> from, dir;  // chord start, end - start, in `axes`
    std::array<double, kMaxChords> inv_len2, slack_mm;
    int count = 0;
    int corner_chord = 0;  // the last chord of `before`, ending at the corner
};
CornerPath corner_path(const Element& before, double before_mm, const Element& after,
                       double after_mm, double limit_mm) noexcept;

// True only if every point of the Bezier is within limit_mm of the path: the curve is split in
// halves (de Casteljau) until each piece's control points, whose hull holds the piece, lie
// within limit_mm - slack of one chord (the distance to a segment is convex, so the hull's
// farthest point is a control point). Gives up (false) at once when a split point cannot be
// within reach of any chord, or after 6 levels of splitting. Exact for axes the path does not
// move (the blend's values there count as distance). Noexcept, no allocation.
bool bezier_within(const BezierPoints& bezier, const CornerPath& path, double limit_mm) noexcept;

// corner_bezier_points(p0, t1, p3, t2, l_mm) and, if it gives points, bezier_within(them, path,
// limit_mm): true and `out` set exactly when both succeed (out is left alone otherwise), for a
// blend between the path's two moves: p0, t1 must be a point and tangent evaluate() gave of
// `before`, p3, t2 of `after`. Then, when path.still_at_rest, the axes neither move changes add
// exact zeros to every sum and distance, so the work is done in the path's axes only and the
// full points are built only once proved.
bool corner_bezier_within(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                          const AxisArray& t2, double l_mm, const CornerPath& path,
                          double limit_mm, BezierPoints& out) noexcept;

// corner_bezier_within() with the same result, for a Bezier that may lie along one of the
// moves as a whole, such as the offset corner's lane changes from and back onto a line
// (Planner::offset_corner): when path.still_at_rest and its four control points lie well
// within the limit of one chord (within 1 - 1e-5 of it, coordinates within 1e7 times it), the
// proof by halves is skipped, as it would succeed: the rounding argument is at
// Proof::surely_near_chord in geometry.cpp. Otherwise it is corner_bezier_within().
bool shift_bezier_within(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                         const AxisArray& t2, double l_mm, const CornerPath& path, double limit_mm,
                         BezierPoints& out) noexcept;

// bezier_within(b, path, limit_mm) for a Bezier whose four points equal path.fixed in the axes
// neither move changes (as numbers: +0 and -0 alike), such as one built from the moves' points
// and tangents: when path.still_at_rest those axes add exact zeros to every distance, so the
// proof runs in the path's axes only.
bool corner_piece_within(const BezierPoints& b, const CornerPath& path, double limit_mm) noexcept;

// corner_piece_within() with the same result, for a piece that may lie near one chord as a
// whole (a one-sided offset corner's turn split where it passes from one move to the other,
// Planner::one_sided_offset_corner): when path.still_at_rest the whole hull is tried against
// each chord first, as shift_bezier_within does (Proof::surely_near_chord in geometry.cpp).
bool corner_part_within(const BezierPoints& b, const CornerPath& path, double limit_mm) noexcept;

// out = make_bezier(b.p0, b.p1, b.p2, b.p3), written in place, for points corner_bezier_within()
// gave for this path (or any whose points equal path.fixed in the still axes, as for
// corner_piece_within): when path.still_at_rest they do not differ in the still axes, so the
// length's sums run over the path's axes only.
void make_corner_bezier(const BezierPoints& b, const CornerPath& path, Element& out) noexcept;

}  // namespace motion
