#pragma once
// Plane geometry of programmed moves and their offset curves, for compensator.cpp.
// A curve is parametrised by u ∈ [0, 1] from its start to its end.

#include <optional>
#include <vector>

#include "interp/cutter_comp.hpp"

namespace interp::cutter::geom {

double cross(const Vec2& a, const Vec2& b);

/// A programmed move in the plane, from the previous end point.
struct Segment {
    Shape shape = Shape::Line;
    Vec2 start{0, 0};
    Vec2 end{0, 0};
    Vec2 centre{0, 0};
    bool ccw = false;
    double radius = 0.0;       // arcs
    double start_angle = 0.0;  // arcs, rad
    double sweep = 0.0;        // arcs, rad, > 0 (2π for a full circle)
    double h0 = 0.0;
    double h1 = 0.0;

    static Segment make(const Vec2& start, double start_h, const Move& move);
    /// True when the move has no extent in the plane (a Z-only line).
    bool degenerate() const;
    Vec2 tangent(double u) const;  // unit
    Vec2 point(double u) const;
    /// Exact distance from p to the segment (not to its line or full circle).
    double distance(const Vec2& p) const;
};

/// The offset of a Segment by a signed distance (+ left of travel, − right).
struct Curve {
    Shape shape = Shape::Line;
    Vec2 p0{0, 0};   // lines
    Vec2 dir{1, 0};  // lines, unit
    double len = 0.0;
    Vec2 centre{0, 0};  // arcs
    double radius = 0.0;
    double start_angle = 0.0;
    double sweep = 0.0;
    bool ccw = false;
    double h0 = 0.0;
    double h1 = 0.0;

    Vec2 at(double u) const;
    double h_at(double u) const { return h0 + (h1 - h0) * u; }
    /// Parameter of a point lying on the curve's line/circle; outside [0, 1]
    /// when it lies before the start or after the end.
    double param(const Vec2& p) const;
    /// A parameter tolerance equivalent to 1e-7 mm along the curve.
    double tol_u() const;
    /// The piece between u0 and u1 as an output move (role and tag left default).
    OutMove piece(double u0, double u1) const;
};

/// nullopt when an arc's offset radius would be ≤ 0 (tool larger than the arc).
std::optional<Curve> offset(const Segment& seg, double signed_radius);

/// Intersections of the infinite lines / full circles carrying two curves.
std::vector<Vec2> intersections(const Curve& a, const Curve& b);

/// Intersection of two lines given by point and direction; nullopt when parallel.
std::optional<Vec2> line_line(const Vec2& p, const Vec2& d, const Vec2& q, const Vec2& e);

}  // namespace interp::cutter::geom
