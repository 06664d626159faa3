#include "offset_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace interp::cutter::geom {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kPointTolMm = 1e-9;
constexpr double kParamTolMm = 1e-7;

double wrap_positive(double angle) {
    angle = std::fmod(angle, kTwoPi);
    return angle < 0 ? angle + kTwoPi : angle;
}

double angle_of(const Vec2& v) {
    return std::atan2(v.y(), v.x());
}

Vec2 unit_at(double angle) {
    return {std::cos(angle), std::sin(angle)};
}

double direction(bool ccw) {
    return ccw ? 1.0 : -1.0;
}

}  // namespace

double cross(const Vec2& a, const Vec2& b) {
    return a.x() * b.y() - a.y() * b.x();
}

Segment Segment::make(const Vec2& start, double start_h, const Move& move) {
    Segment s;
    s.shape = move.shape;
    s.start = start;
    s.end = move.end;
    s.h0 = start_h;
    s.h1 = move.end_h;
    if (move.shape == Shape::Arc) {
        s.centre = move.centre;
        s.ccw = move.ccw;
        s.radius = (start - move.centre).norm();
        s.start_angle = angle_of(start - move.centre);
        const double end_angle = angle_of(move.end - move.centre);
        s.sweep = wrap_positive(direction(move.ccw) * (end_angle - s.start_angle));
        if (s.sweep < 1e-12) s.sweep = kTwoPi;  // start == end: a full circle
    }
    return s;
}

bool Segment::degenerate() const {
    if (shape == Shape::Arc) return radius <= kPointTolMm;
    return (end - start).norm() <= kPointTolMm;
}

Vec2 Segment::tangent(double u) const {
    if (shape == Shape::Line) return (end - start).normalized();
    const double a = start_angle + direction(ccw) * sweep * u;
    const Vec2 radial = unit_at(a);
    return ccw ? Vec2(-radial.y(), radial.x()) : Vec2(radial.y(), -radial.x());
}

Vec2 Segment::point(double u) const {
    if (shape == Shape::Line) return start + (end - start) * u;
    return centre + radius * unit_at(start_angle + direction(ccw) * sweep * u);
}

double Segment::distance(const Vec2& p) const {
    if (shape == Shape::Line) {
        const Vec2 d = end - start;
        const double len2 = d.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - start).dot(d) / len2, 0.0, 1.0) : 0.0;
        return (p - (start + d * t)).norm();
    }
    const double a = wrap_positive(direction(ccw) * (angle_of(p - centre) - start_angle));
    if (a <= sweep) return std::abs((p - centre).norm() - radius);
    return std::min((p - start).norm(), (p - end).norm());
}

Vec2 Curve::at(double u) const {
    if (shape == Shape::Line) return p0 + dir * (len * u);
    return centre + radius * unit_at(start_angle + direction(ccw) * sweep * u);
}

double Curve::param(const Vec2& p) const {
    if (shape == Shape::Line) return (p - p0).dot(dir) / len;
    double a = wrap_positive(direction(ccw) * (angle_of(p - centre) - start_angle));
    // Angles beyond the end are split halfway through the missing part of the
    // circle: nearer the end counts as "after", nearer the start as "before".
    if (a > sweep && a - sweep > (kTwoPi - sweep) / 2.0) a -= kTwoPi;
    return a / sweep;
}

double Curve::tol_u() const {
    const double length = shape == Shape::Line ? len : radius * sweep;
    return length > 0 ? kParamTolMm / length : 1.0;
}

OutMove Curve::piece(double u0, double u1) const {
    OutMove m;
    m.shape = shape;
    m.start = at(u0);
    m.end = at(u1);
    m.start_h = h_at(u0);
    m.end_h = h_at(u1);
    if (shape == Shape::Arc) {
        m.centre = centre;
        m.ccw = ccw;
        m.sweep_rad = sweep * (u1 - u0);
    }
    return m;
}

std::optional<Curve> offset(const Segment& seg, double signed_radius) {
    Curve c;
    c.shape = seg.shape;
    c.h0 = seg.h0;
    c.h1 = seg.h1;
    if (seg.shape == Shape::Line) {
        c.dir = (seg.end - seg.start).normalized();
        c.len = (seg.end - seg.start).norm();
        const Vec2 left(-c.dir.y(), c.dir.x());
        c.p0 = seg.start + left * signed_radius;
        return c;
    }
    // The left of a CCW arc is its centre: moving left shrinks the radius.
    c.radius = seg.radius - direction(seg.ccw) * signed_radius;
    if (c.radius <= kPointTolMm) return std::nullopt;
    c.centre = seg.centre;
    c.ccw = seg.ccw;
    c.start_angle = seg.start_angle;
    c.sweep = seg.sweep;
    return c;
}

std::optional<Vec2> line_line(const Vec2& p, const Vec2& d, const Vec2& q, const Vec2& e) {
    const double den = cross(d, e);
    if (std::abs(den) < 1e-15) return std::nullopt;
    const double t = cross(q - p, e) / den;
    return p + d * t;
}

namespace {

std::vector<Vec2> line_circle(const Curve& line, const Curve& circle) {
    // |p0 + t·dir − c|² = ρ²  with |dir| = 1.
    const Vec2 f = line.p0 - circle.centre;
    const double b = f.dot(line.dir);
    const double c = f.squaredNorm() - circle.radius * circle.radius;
    double disc = b * b - c;
    // A tangent contact computed slightly negative is still a contact.
    if (disc < 0 && disc > -1e-9 * std::max(1.0, circle.radius * circle.radius)) disc = 0;
    if (disc < 0) return {};
    const double root = std::sqrt(disc);
    return {line.p0 + line.dir * (-b - root), line.p0 + line.dir * (-b + root)};
}

std::vector<Vec2> circle_circle(const Curve& a, const Curve& b) {
    const Vec2 d = b.centre - a.centre;
    const double dist = d.norm();
    if (dist < kPointTolMm) return {};
    const double x = (dist * dist + a.radius * a.radius - b.radius * b.radius) / (2.0 * dist);
    double h2 = a.radius * a.radius - x * x;
    if (h2 < 0 && h2 > -1e-9 * std::max(1.0, a.radius * a.radius)) h2 = 0;
    if (h2 < 0) return {};
    const Vec2 ud = d / dist;
    const Vec2 base = a.centre + ud * x;
    const Vec2 perp(-ud.y(), ud.x());
    const double h = std::sqrt(h2);
    return {base + perp * h, base - perp * h};
}

}  // namespace

std::vector<Vec2> intersections(const Curve& a, const Curve& b) {
    if (a.shape == Shape::Line && b.shape == Shape::Line) {
        if (auto p = line_line(a.p0, a.dir, b.p0, b.dir)) return {*p};
        return {};
    }
    if (a.shape == Shape::Line) return line_circle(a, b);
    if (b.shape == Shape::Line) return line_circle(b, a);
    return circle_circle(a, b);
}

}  // namespace interp::cutter::geom
