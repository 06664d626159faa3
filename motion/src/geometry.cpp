#include "motion/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <string>

namespace motion {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
// The interpreter's default ARC_TOLERANCE_MM (FEATURES ARC-11).
constexpr double kArcEndOffCircle_mm = 0.01;

double norm(const AxisArray& v) {
    double s = 0;
    for (double x : v) s += x * x;
    return std::sqrt(s);
}

// Which axes a loop runs over: all nine, or a list.
struct AllAxes {
    static constexpr int count() { return kAxes; }
    constexpr int operator[](int j) const { return j; }
};
struct ListedAxes {
    const int* axes;
    int n;
    int count() const { return n; }
    int operator[](int j) const { return axes[j]; }
};

// Each evaluator computes the derivatives up to Order (0 = position only, ... 3 = all); the
// planner asks for positions and tangents far more often than the sampler asks for all of it.
// Every expression is the same whatever the order, so the values do not depend on it.
template <int Order>
void eval_line(const Element& e, double s, CurvePoint& out) {
    for (int k = 0; k < kAxes; ++k) {
        out.p[k] = e.origin[k] + s * e.a[k];
        if constexpr (Order >= 1) out.d1[k] = e.a[k];
        if constexpr (Order >= 2) out.d2[k] = 0;
        if constexpr (Order >= 3) out.d3[k] = 0;
    }
}

template <int Order>
void eval_arc(const Element& e, double s, CurvePoint& out) {
    double k1 = e.sweep_rad / e.length_mm;  // d theta / ds
    double th = e.theta0_rad + k1 * s;
    double cs = std::cos(th), sn = std::sin(th);
    double r = e.radius_mm, f = s / e.length_mm;
    for (int k = 0; k < kAxes; ++k) {
        double radial = cs * e.a[k] + sn * e.b[k];
        double tang = -sn * e.a[k] + cs * e.b[k];
        out.p[k] = e.origin[k] + r * radial + f * e.c[k];
        if constexpr (Order >= 1) out.d1[k] = r * k1 * tang + e.c[k] / e.length_mm;
        if constexpr (Order >= 2) out.d2[k] = -r * k1 * k1 * radial;
        if constexpr (Order >= 3) out.d3[k] = -r * k1 * k1 * k1 * tang;
    }
}

template <int Order>
void eval_blend(const Element& e, double s, CurvePoint& out) {
    double two_l = e.length_mm;
    double u = s / two_l;
    double sigma = u * u * (3 - 2 * u);
    double integral = u * u * u * (1 - u / 2);  // int_0^u sigma
    double dsigma = 6 * u * (1 - u) / two_l;
    double ddsigma = (6 - 12 * u) / (two_l * two_l);
    for (int k = 0; k < kAxes; ++k) {
        out.p[k] = e.origin[k] + two_l * (u * e.a[k] + integral * e.b[k]);
        if constexpr (Order >= 1) out.d1[k] = e.a[k] + sigma * e.b[k];
        if constexpr (Order >= 2) out.d2[k] = dsigma * e.b[k];
        if constexpr (Order >= 3) out.d3[k] = ddsigma * e.b[k];
    }
}

template <int Order>
void eval_bezier(const Element& e, double s, CurvePoint& out) {
    double L = e.length_mm;
    double u = s / L, w = 1 - u;
    double b0 = w * w * w, b1 = 3 * u * w * w, b2 = 3 * u * u * w, b3 = u * u * u;
    for (int k = 0; k < kAxes; ++k) {
        double p0 = e.origin[k], p1 = e.a[k], p2 = e.b[k], p3 = e.end[k];
        double d0 = p1 - p0, d1 = p2 - p1, d2 = p3 - p2;
        out.p[k] = b0 * p0 + b1 * p1 + b2 * p2 + b3 * p3;
        if constexpr (Order >= 1) out.d1[k] = 3 * (w * w * d0 + 2 * u * w * d1 + u * u * d2) / L;
        if constexpr (Order >= 2) out.d2[k] = 6 * (w * (d1 - d0) + u * (d2 - d1)) / (L * L);
        if constexpr (Order >= 3) out.d3[k] = 6 * (d2 - 2 * d1 + d0) / (L * L * L);
    }
}

template <int Order>
void evaluate_to(const Element& e, double s, CurvePoint& out) noexcept {
    s = std::clamp(s, 0.0, e.length_mm);
    switch (e.kind) {
        case ElementKind::Line:
            eval_line<Order>(e, s, out);
            break;
        case ElementKind::Arc:
            eval_arc<Order>(e, s, out);
            break;
        case ElementKind::Blend:
            eval_blend<Order>(e, s, out);
            break;
        case ElementKind::Bezier:
            eval_bezier<Order>(e, s, out);
            break;
    }
    if (s >= e.length_mm) out.p = e.end;  // the programmed end point, free of rounding
}

}  // namespace

void evaluate(const Element& e, double s, CurvePoint& out) noexcept {
    evaluate_to<3>(e, s, out);
}

void evaluate_upto(const Element& e, double s_mm, int order, CurvePoint& out) noexcept {
    switch (order) {
        case 0:
            evaluate_to<0>(e, s_mm, out);
            return;
        case 1:
            evaluate_to<1>(e, s_mm, out);
            return;
        case 2:
            evaluate_to<2>(e, s_mm, out);
            return;
        default:
            evaluate_to<3>(e, s_mm, out);
    }
}

AxisArray point_at(const Element& e, double s_mm) noexcept {
    CurvePoint cp;
    evaluate_to<0>(e, s_mm, cp);
    return cp.p;
}

namespace {

// A Bezier curve's derivatives are Bezier curves too and stay within the hull of their control
// points: the factors of the hodographs' control points (1 / length per derivative).
struct BezierFactors {
    double s1, s2, s3;
};

BezierFactors bezier_factors(const Element& e) {
    const double inv_l = 1 / e.length_mm;
    const double s2 = 6 * inv_l * inv_l;
    return {3 * inv_l, s2, s2 * inv_l};
}

// Inlined: as a call per axis it cost more than its work.
[[gnu::always_inline]] inline void bezier_axis_bounds(const Element& e, int k,
                                                      const BezierFactors& f, ElementBounds& b) {
    double d0 = e.a[k] - e.origin[k], d1 = e.b[k] - e.a[k], d2 = e.end[k] - e.b[k];
    // max(max(.)) is std::max({.}): the same comparisons in the same order.
    b.g1[k] = b.linear[k] = f.s1 * std::max(std::max(std::fabs(d0), std::fabs(d1)), std::fabs(d2));
    b.g2[k] = f.s2 * std::max(std::fabs(d1 - d0), std::fabs(d2 - d1));
    b.g3[k] = f.s3 * std::fabs(d2 - 2 * d1 + d0);
    b.tangential_in_plane[k] = 0;
}

// Lists, in the order given, the axes among `ax` whose bounds are not all 0. g1 is the sum
// (arcs) or the value (others) of tangential_in_plane and linear, so g1, g2 and g3 cover all
// five. The entry past the last listed axis is overwritten freely.
template <class Axes>
void list_moving_axes(ElementBounds& b, Axes ax) {
    std::uint64_t bits[kAxes];
    for (int j = 0; j < ax.count(); ++j) {
        const int k = ax[j];
        std::uint64_t x, y, z;
        std::memcpy(&x, &b.g1[k], 8);
        std::memcpy(&y, &b.g2[k], 8);
        std::memcpy(&z, &b.g3[k], 8);
        bits[j] = x | y | z;
    }
    int n = 0;
    for (int j = 0; j < ax.count(); ++j) {
        b.axes[n] = static_cast<std::uint8_t>(ax[j]);
        n += bits[j] != 0;
    }
    b.axis_count = n;
}

// bounds(e) written into b (every member). Inlined: bounds(e) is called for every line the
// planner adds, where a call more costs as much as the zeros of the line case.
[[gnu::always_inline]] inline void bounds_into(const Element& e, ElementBounds& b) {
    switch (e.kind) {
        case ElementKind::Line:
            // Whole arrays: a loop storing the zeros became one rep stos over all three, whose
            // start-up cost more than the stores.
            b.g2 = {};
            b.g3 = {};
            b.tangential_in_plane = {};
            for (int k = 0; k < kAxes; ++k) b.g1[k] = b.linear[k] = std::fabs(e.a[k]);
            break;
        case ElementKind::Arc: {
            double k1 = std::fabs(e.sweep_rad / e.length_mm);
            double r = e.radius_mm, inv_len = 1 / e.length_mm;
            for (int k = 0; k < kAxes; ++k) {
                // amplitude of the rotating component
                double q = std::sqrt(e.a[k] * e.a[k] + e.b[k] * e.b[k]);
                b.tangential_in_plane[k] = r * k1 * q;
                b.linear[k] = std::fabs(e.c[k]) * inv_len;
                b.g1[k] = b.tangential_in_plane[k] + b.linear[k];
                b.g2[k] = r * k1 * k1 * q;
                b.g3[k] = r * k1 * k1 * k1 * q;
            }
            break;
        }
        case ElementKind::Blend: {
            double inv_two_l = 1 / e.length_mm;
            for (int k = 0; k < kAxes; ++k) {
                double t2 = e.a[k] + e.b[k];
                b.g1[k] = b.linear[k] = std::max(std::fabs(e.a[k]), std::fabs(t2));
                b.g2[k] = 1.5 * std::fabs(e.b[k]) * inv_two_l;
                b.g3[k] = 6 * std::fabs(e.b[k]) * inv_two_l * inv_two_l;
                b.tangential_in_plane[k] = 0;
            }
            break;
        }
        case ElementKind::Bezier: {
            const BezierFactors f = bezier_factors(e);
            for (int k = 0; k < kAxes; ++k) bezier_axis_bounds(e, k, f, b);
            break;
        }
    }
    list_moving_axes(b, AllAxes{});
}

}  // namespace

ElementBounds bounds(const Element& e) noexcept {
    ElementBounds b;
    bounds_into(e, b);
    return b;
}

void bounds_into(const Element& e, std::span<const int> moving, ElementBounds& b) noexcept {
    const BezierFactors f = bezier_factors(e);
    if (e.kind != ElementKind::Bezier ||
        !(std::isfinite(f.s1) && std::isfinite(f.s2) && std::isfinite(f.s3))) {
        bounds_into(e, b);
        return;
    }
    // Whole arrays (vector stores; a loop would become rep stos, see the lines above).
    b.g1 = {};
    b.g2 = {};
    b.g3 = {};
    b.tangential_in_plane = {};
    b.linear = {};
    for (int k : moving) bezier_axis_bounds(e, k, f, b);
    list_moving_axes(b, ListedAxes{moving.data(), static_cast<int>(moving.size())});
}

ElementBounds bounds(const Element& e, std::span<const int> moving) noexcept {
    ElementBounds b;  // one object on every path, built where the caller wants it
    bounds_into(e, moving, b);
    return b;
}

// The Elements here are built with every member given, the zero arrays as copies of a
// variable: `Element e;` and member stores cleared all 400 bytes first (its default member
// initialisers), and so did an aggregate with `AxisArray{}` members (GCC clears a whole object
// before its initialiser when that has enough zeros), both with rep stos, whose start-up cost
// more than the stores (a quarter of make_line's time on tp_default).
Element make_line(const AxisArray& start, const AxisArray& end) noexcept {
    AxisArray d, a, zero{};
    for (int k = 0; k < kAxes; ++k) d[k] = end[k] - start[k];
    const double length = norm(d);
    for (int k = 0; k < kAxes; ++k) a[k] = length > 0 ? d[k] / length : 0;
    return Element{ElementKind::Line, length, start, a, zero, zero, end, 0, 0, 0};
}

// The signed sweep from angle th0 to th1 in the direction and with the extra whole turns of
// `turns` (G2 < 0 < G3; |turns| > 1 adds circles).
double arc_sweep(double th0, double th1, int turns) {
    double sweep = th1 - th0;
    const int extra = std::abs(turns) - 1;
    if (turns > 0) {
        if (sweep <= 1e-12) sweep += kTwoPi;
        return sweep + kTwoPi * extra;
    }
    if (sweep >= -1e-12) sweep -= kTwoPi;
    return sweep - kTwoPi * extra;
}

struct PlaneArc {
    double cu, cv, r, th0, sweep;
    double u(double th) const { return cu + r * std::cos(th); }
    double v(double th) const { return cv + r * std::sin(th); }
};

// Distance from (pu, pv) to the arc (not its whole circle).
double distance_to_arc(double pu, double pv, const PlaneArc& a) {
    if (std::fabs(a.sweep) < kTwoPi) {
        const double phi = std::atan2(pv - a.cv, pu - a.cu);
        double into = a.sweep > 0 ? phi - a.th0 : a.th0 - phi;  // how far along, either way round
        into = std::fmod(std::fmod(into, kTwoPi) + kTwoPi, kTwoPi);
        if (into > std::fabs(a.sweep)) {
            const double end = a.th0 + a.sweep;
            return std::min(std::hypot(pu - a.u(a.th0), pv - a.v(a.th0)),
                            std::hypot(pu - a.u(end), pv - a.v(end)));
        }
    }
    return std::fabs(std::hypot(pu - a.cu, pv - a.cv) - a.r);
}

// How far apart two arcs are (each point of either to the other, sampled finely): what moving
// an arc's centre does to its path. Rarely needed, so plain sampling.
double arcs_apart(const PlaneArc& a, const PlaneArc& b) {
    const int n = 32 * static_cast<int>(std::ceil(std::max(std::fabs(a.sweep), std::fabs(b.sweep)) /
                                                  (kTwoPi / 8)));
    double apart = 0;
    for (int k = 0; k <= n; ++k) {
        const double f = static_cast<double>(k) / n;
        const double tha = a.th0 + f * a.sweep, thb = b.th0 + f * b.sweep;
        apart = std::max({apart, distance_to_arc(a.u(tha), a.v(tha), b),
                          distance_to_arc(b.u(thb), b.v(thb), a)});
    }
    return apart;
}

Element make_arc(const AxisArray& start, const PathSegment& seg) {
    int i = seg.plane_first, j = seg.plane_second, n = seg.plane_normal;
    auto valid = [](int ax) { return ax >= 0 && ax < kAxes; };
    if (!valid(i) || !valid(j) || !valid(n) || i == j || i == n || j == n)
        throw PlanError(seg.line, "arc plane axes must be three different axes");
    if (seg.turns == 0) throw PlanError(seg.line, "arc with zero turns");
    double cu = seg.centre_mm[0], cv = seg.centre_mm[1];
    double su = start[i] - cu, sv = start[j] - cv;
    double eu = seg.end_mm[i] - cu, ev = seg.end_mm[j] - cv;
    double r0 = std::hypot(su, sv), r1 = std::hypot(eu, ev);
    if (r0 < 1e-9) throw PlanError(seg.line, "arc radius is zero (centre at the start point)");
    // LinuxCNC-like acceptance: small rounding of the programmed end is absorbed by moving the
    // centre onto the chord's perpendicular bisector; anything larger is a programming error.
    // The allowance is the interpreter's default (ARC_TOLERANCE_MM, 0.01 mm), so that what
    // `cnc check` accepts runs.
    const double mismatch = std::fabs(r1 - r0), allowed_mm = std::max(kArcEndOffCircle_mm, 1e-3 * r0);
    if (mismatch > allowed_mm)
        throw PlanError(seg.line, "arc end is not on the circle: start radius " +
                                      std::to_string(r0) + " mm, end radius " + std::to_string(r1) +
                                      " mm");
    const double chord_u = seg.end_mm[i] - start[i], chord_v = seg.end_mm[j] - start[j];
    const double chord = std::hypot(chord_u, chord_v);
    if (mismatch > 0 && chord > 1e-9) {
        const double pcu = cu, pcv = cv, psu = su, psv = sv, peu = eu, pev = ev, pr = r0;
        const double mu = (start[i] + seg.end_mm[i]) / 2, mv = (start[j] + seg.end_mm[j]) / 2;
        const double nu = -chord_v / chord, nv = chord_u / chord;  // bisector direction
        const double t = (cu - mu) * nu + (cv - mv) * nv;
        const double moved_mm = std::hypot(mu + t * nu - cu, mv + t * nv - cv);
        cu = mu + t * nu;
        cv = mv + t * nv;
        su = start[i] - cu, sv = start[j] - cv;
        eu = seg.end_mm[i] - cu, ev = seg.end_mm[j] - cv;
        r0 = std::hypot(su, sv);
        // Every point of the moved circle is within moved + |r0 change| of the programmed one,
        // which settles almost every arc at once. A short chord can move the centre far: on a
        // short arc the path hardly changes, but a nearly full circle whose end is a little off
        // its start becomes another circle through the two close points, a dot (X100 Y100,
        // G2 X100.004 Y100 I-5: radius 0.002 mm). Such an arc is refused, not run.
        if (moved_mm + std::fabs(r0 - pr) > allowed_mm) {
            const PlaneArc programmed{pcu, pcv, pr, std::atan2(psv, psu),
                                      arc_sweep(std::atan2(psv, psu), std::atan2(pev, peu), seg.turns)};
            const PlaneArc moved{cu, cv, r0, std::atan2(sv, su),
                                 arc_sweep(std::atan2(sv, su), std::atan2(ev, eu), seg.turns)};
            const double apart_mm = arcs_apart(programmed, moved);
            if (apart_mm > allowed_mm)
                throw PlanError(seg.line,
                                "arc end is " + std::to_string(mismatch) +
                                    " mm off the circle, and the only circle through both ends "
                                    "leaves the programmed arc by " +
                                    std::to_string(apart_mm) +
                                    " mm (a nearly full circle): program the end on the circle");
        }
    }
    const double th0 = std::atan2(sv, su), th1 = std::atan2(ev, eu);
    const double sweep = arc_sweep(th0, th1, seg.turns);
    // Built with every member given (see make_line): `Element e;` cleared it with rep stos.
    AxisArray origin = start, a{}, b{}, c;
    origin[i] = cu;
    origin[j] = cv;
    a[i] = 1;
    b[j] = 1;
    for (int k = 0; k < kAxes; ++k) c[k] = (k == i || k == j) ? 0 : seg.end_mm[k] - start[k];
    return Element{ElementKind::Arc,
                   std::hypot(r0 * sweep, norm(c)),
                   origin,
                   a,
                   b,
                   c,
                   seg.end_mm,
                   r0,
                   th0,
                   sweep};
}

Element make_blend(const AxisArray& corner, const AxisArray& t1, const AxisArray& t2,
                   double l) noexcept {
    AxisArray origin, a, b, end, zero{};  // zero: see make_line
    for (int k = 0; k < kAxes; ++k) {
        origin[k] = corner[k] - l * t1[k];
        a[k] = t1[k];
        b[k] = t2[k] - t1[k];
        end[k] = corner[k] + l * t2[k];
    }
    return Element{ElementKind::Blend, 2 * l, origin, a, b, zero, end, 0, 0, 0};
}

namespace {

// A Bezier's pseudo length (see make_bezier), summed over the listed axes (Axes as for the
// evaluators).
template <class Axes>
double bezier_length_in(const AxisArray& p0, const AxisArray& p1, const AxisArray& p2,
                        const AxisArray& p3, Axes ax) {
    double n0 = 0, n1 = 0, n2 = 0;
    for (int j = 0; j < ax.count(); ++j) {
        const int k = ax[j];
        n0 += (p1[k] - p0[k]) * (p1[k] - p0[k]);
        n1 += (p2[k] - p1[k]) * (p2[k] - p1[k]);
        n2 += (p3[k] - p2[k]) * (p3[k] - p2[k]);
    }
    return 3 * std::sqrt(std::max({n0, n1, n2}));
}

}  // namespace

Element make_bezier(const AxisArray& p0, const AxisArray& p1, const AxisArray& p2,
                    const AxisArray& p3) noexcept {
    AxisArray zero{};  // see make_line
    return Element{ElementKind::Bezier, bezier_length_in(p0, p1, p2, p3, AllAxes{}), p0, p1, p2,
                   zero,                 p3, 0, 0, 0};
}

void make_corner_bezier(const BezierPoints& b, const CornerPath& path, Element& out) noexcept {
    // Every member as make_bezier's new Element has it.
    out.kind = ElementKind::Bezier;
    out.origin = b.p0;
    out.a = b.p1;
    out.b = b.p2;
    out.end = b.p3;
    out.c = {};
    out.radius_mm = 0;
    out.theta0_rad = 0;
    out.sweep_rad = 0;
    // The still axes' differences are +-0 (corner_bezier_within), which add nothing.
    out.length_mm =
        path.still_at_rest
            ? bezier_length_in(b.p0, b.p1, b.p2, b.p3, ListedAxes{path.axes.data(), path.dims})
            : bezier_length_in(b.p0, b.p1, b.p2, b.p3, AllAxes{});
}

Element make_parabola(const AxisArray& corner, const AxisArray& t1, const AxisArray& t2,
                      double l) noexcept {
    AxisArray p0, p1, p2, p3;
    for (int k = 0; k < kAxes; ++k) {
        p0[k] = corner[k] - l * t1[k];
        p3[k] = corner[k] + l * t2[k];
        p1[k] = p0[k] + 2 * l / 3 * t1[k];
        p2[k] = p3[k] - 2 * l / 3 * t2[k];
    }
    return make_bezier(p0, p1, p2, p3);
}

Element trim_arc(const Element& arc, double from, double to, const AxisArray* end_mm) noexcept {
    // Built with every member given (see make_line): `Element e = arc;` copied all 400 bytes
    // with rep movs, half of this function's time, before most were written again.
    const double len = arc.length_mm;
    const double keep = std::max(0.0, len - from - to);
    const AxisArray end = to > 0 ? (end_mm ? *end_mm : point_at(arc, len - to)) : arc.end;
    // origin holds the centre in the plane and the start's values off it (c is zero in-plane).
    const double f0 = from / len;
    AxisArray origin, c;
    for (int k = 0; k < kAxes; ++k) origin[k] = arc.origin[k] + f0 * arc.c[k];
    for (int k = 0; k < kAxes; ++k) c[k] = arc.c[k] * keep / len;
    return Element{arc.kind,
                   keep,
                   origin,
                   arc.a,
                   arc.b,
                   c,
                   end,
                   arc.radius_mm,
                   arc.theta0_rad + arc.sweep_rad * f0,
                   arc.sweep_rad * keep / len};
}

namespace {

EndDerivs derivs_at(const Element& e, double s, bool with_d2) {
    // A line's tangent is its direction and its p'' is +0 (eval_line), wherever s is: the
    // point, which is not needed here, was most of the cost (classify() asks at every junction).
    if (e.kind == ElementKind::Line) return {e.a, AxisArray{}};
    CurvePoint cp;
    if (with_d2) {
        evaluate_to<2>(e, s, cp);
        return {cp.d1, cp.d2};
    }
    evaluate_to<1>(e, s, cp);
    return {cp.d1, {}};
}

}  // namespace

EndDerivs start_derivs(const Element& e, bool with_d2) noexcept {
    return derivs_at(e, 0, with_d2);
}

EndDerivs end_derivs(const Element& e, bool with_d2) noexcept {
    return derivs_at(e, e.length_mm, with_d2);
}

Element trim_line(const Element& line, double from, double to) noexcept {
    // Built with every member given (see make_line): `Element e = line;` copied all 400 bytes
    // with rep movs, half of this function's time, before most were written again.
    AxisArray origin, end;
    for (int k = 0; k < kAxes; ++k) origin[k] = line.origin[k] + from * line.a[k];
    if (to > 0)
        for (int k = 0; k < kAxes; ++k) end[k] = line.end[k] - to * line.a[k];
    else
        end = line.end;
    return Element{line.kind, std::max(0.0, line.length_mm - from - to),
                   origin,    line.a,
                   line.b,    line.c,
                   end,       line.radius_mm,
                   line.theta0_rad, line.sweep_rad};
}

namespace {

// The inner control points' distance h along the tangents for corner_bezier_points, from the
// sums dd = |p3 - p0|^2, ds = (p3 - p0).(t1 + t2), ss = |t1 + t2|^2; 0 if no h fits.
double corner_bezier_h(double dd, double ds, double ss, double l) {
    const double h0 = 2.0 / 3 * l;
    // The hodograph's middle control point is p3 - p0 - h (t1 + t2); its length may not
    // exceed h: f(h) = (ss - 1) h^2 - 2 ds h + dd <= 0.
    auto f = [&](double h) { return (ss - 1) * h * h - 2 * ds * h + dd; };
    double h = 0;
    const double qa = ss - 1, disc = ds * ds - qa * dd;
    if (f(h0) <= 0) {
        h = h0;
    } else if (std::fabs(qa) < 1e-12) {
        h = ds > 0 ? std::max(h0, dd / (2 * ds)) : 0.0;
    } else if (disc >= 0) {
        double r1 = (ds - std::sqrt(disc)) / qa, r2 = (ds + std::sqrt(disc)) / qa;
        for (double r : {std::min(r1, r2), std::max(r1, r2)}) {
            if (r > h0 && f(r * (1 + 1e-12)) <= 1e-12 * dd) {
                h = r * (1 + 1e-12);
                break;
            }
        }
    }
    return h > 0 ? h : 0;
}

void set_corner_bezier(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                       const AxisArray& t2, double h, BezierPoints& b) {
    b.p0 = p0;
    b.p3 = p3;
    for (int k = 0; k < kAxes; ++k) {
        b.p1[k] = p0[k] + h * t1[k];
        b.p2[k] = p3[k] - h * t2[k];
    }
}

}  // namespace

std::optional<BezierPoints> corner_bezier_points(const AxisArray& p0, const AxisArray& t1,
                                                 const AxisArray& p3, const AxisArray& t2,
                                                 double l) noexcept {
    double dd = 0, ds = 0, ss = 0;
    for (int k = 0; k < kAxes; ++k) {
        double d = p3[k] - p0[k], sk = t1[k] + t2[k];
        dd += d * d, ds += d * sk, ss += sk * sk;
    }
    const double h = corner_bezier_h(dd, ds, ss, l);
    if (!(h > 0)) return std::nullopt;
    BezierPoints b;
    set_corner_bezier(p0, t1, p3, t2, h, b);
    return b;
}

namespace {

// Share of the distance to be proved that an arc's chords may give away as slack.
constexpr double kChordSlackShare = 0.02;
// Halvings of a blend before bezier_within gives up (2^6 pieces).
constexpr int kMaxSplitDepth = 6;
// Proof::surely_near_chord: a whole hull counts as proved when its control points lie within
// (1 - 1e-5) of a chord's room (squared: 1 - 2e-5 <= (1 - 1e-5)^2) and no coordinate exceeds
// 1e7 times that room. The rounding argument there needs 300 u S <= 1e-5 room (u = 2^-53),
// that is S <= 3e8 room: 1e7 leaves a factor 30.
constexpr double kWholeHullRoom2Share = 1 - 2e-5;
constexpr double kWholeHullScalePerRoom = 1e7;

// Sets moving[k] for every axis e changes anywhere (and leaves the others as they were).
// The bits of x without its sign: 0 exactly when x == 0 (+0 or -0), nonzero for NaN too.
std::uint64_t magnitude_bits(double x) {
    std::uint64_t u;
    std::memcpy(&u, &x, sizeof u);
    return u << 1;
}

// x != y as an integer, for | without a branch per test (|| would branch on each).
unsigned differs(double x, double y) { return x != y; }

void mark_moving_axes(const Element& e, std::array<bool, kAxes>& moving) {
    // x != 0 as integer tests and | rather than ||: no branch per axis.
    switch (e.kind) {
        case ElementKind::Line:
            for (int k = 0; k < kAxes; ++k) moving[k] |= magnitude_bits(e.a[k]) != 0;
            return;
        case ElementKind::Arc:
            for (int k = 0; k < kAxes; ++k)
                moving[k] |=
                    (magnitude_bits(e.a[k]) | magnitude_bits(e.b[k]) | magnitude_bits(e.c[k])) != 0;
            return;
        case ElementKind::Blend:
            for (int k = 0; k < kAxes; ++k)
                moving[k] |= (magnitude_bits(e.a[k]) | magnitude_bits(e.b[k])) != 0;
            return;
        case ElementKind::Bezier:
            for (int k = 0; k < kAxes; ++k)
                moving[k] |= differs(e.a[k], e.origin[k]) | differs(e.b[k], e.origin[k]) |
                             differs(e.end[k], e.origin[k]);
            return;
    }
    moving.fill(true);
}

// Chords of e over [s0, s1]; `known` is the point at `known_s` (s0 or s1), which saves an
// evaluation: the corner point both moves share.
void add_chords(CornerPath& path, const Element& e, double s0, double s1, double known_s,
                const AxisArray& known, double limit_mm) {
    int n = 1;
    double slack = 0;
    if (e.kind == ElementKind::Arc) {
        double dphi = std::fabs(e.sweep_rad) * (s1 - s0) / e.length_mm;
        double want = dphi * std::sqrt(e.radius_mm / (8 * kChordSlackShare * limit_mm));
        n = std::clamp(int(std::ceil(want)), 1, CornerPath::kMaxChordsPerMove);
        slack = e.radius_mm * (dphi / n) * (dphi / n) / 8;
    }
    // Only the path's axes of the points are read. A line's are point_at()'s, worked out
    // in those axes alone (evaluate_to's clamp, eval_line's expression, the end point at the
    // end): the chords of the lines beside a corner cost no call.
    auto point = [&](int i, AxisArray& out) {
        double s = i == n ? s1 : s0 + (s1 - s0) * i / n;
        if (s == known_s) {
            out = known;
        } else if (e.kind == ElementKind::Line) {
            s = std::clamp(s, 0.0, e.length_mm);
            const bool at_end = s >= e.length_mm;
            for (int j = 0; j < path.dims; ++j) {
                const int k = path.axes[j];
                out[k] = at_end ? e.end[k] : e.origin[k] + s * e.a[k];
            }
        } else {
            out = point_at(e, s);
        }
    };
    AxisArray a{}, b{};  // a line's fill only the path's axes
    point(0, a);
    for (int i = 1; i <= n; ++i, a = b) {
        point(i, b);
        const int c = path.count++;
        double len2 = 0;
        for (int j = 0; j < path.dims; ++j) {
            const int k = path.axes[j];
            path.from[c][j] = a[k];
            path.dir[c][j] = b[k] - a[k];
            len2 += path.dir[c][j] * path.dir[c][j];
        }
        path.inv_len2[c] = len2 > 0 ? 1 / len2 : 0;
        path.slack_mm[c] = slack;
    }
}

// A Bezier piece's control points: first in the path's axes, then (relative to the path's
// fixed value) in the axes only the blend moves.
using Hull = std::array<AxisArray, 4>;

// What bezier_within works with: the path, the limit, the dimensions of the hull points, and
// the squared distance from the path in the axes neither moves (the same for all points).
// PathDims is path.dims and Dims dims when known at compile time (the loops unroll), else 0.
template <int PathDims, int Dims>
struct Proof {
    const CornerPath& path;
    double limit_mm;
    double still_axes2;
    int dims;  // path.dims, then the blend's own axes up to `dims`

    // Squared room left for the distance in the other axes to chord c (< 0: none).
    double room2(int c) const {
        double room = limit_mm - path.slack_mm[c];
        return room > 0 ? room * room - still_axes2 : -1;
    }

    double chord_dist2(int c, const AxisArray& q) const {
        const AxisArray &a = path.from[c], &d = path.dir[c];
        const int n = PathDims > 0 ? PathDims : path.dims;
        double t = 0;
        for (int k = 0; k < n; ++k) t += (q[k] - a[k]) * d[k];
        t = std::clamp(t * path.inv_len2[c], 0.0, 1.0);
        double r = 0;
        for (int k = 0; k < n; ++k) {
            double x = q[k] - a[k] - t * d[k];
            r += x * x;
        }
        const int m = Dims > 0 ? Dims : dims;
        for (int k = n; k < m; ++k) r += q[k] * q[k];  // the chord has 0 there
        return r;
    }

    // Whether all of the piece's control points lie within reach of chord c. The end points
    // first, the last one before all: a piece is tried on its neighbour's chord first, which
    // holds its start and fails, if at all, at its far end.
    bool hull_near_chord(int c, const Hull& q) const {
        const double r2 = room2(c);
        if (r2 < 0) return false;
        return chord_dist2(c, q[3]) <= r2 && chord_dist2(c, q[0]) <= r2 &&
               chord_dist2(c, q[1]) <= r2 && chord_dist2(c, q[2]) <= r2;
    }

    // Whether prove() would succeed on the piece q (in the path's axes only, with
    // still_axes2 == 0) because all of it lies near chord c: every control point within
    // (1 - 1e-5) of the room, and every coordinate S of the points, and |from| + |dir| of the
    // chord, within 1e7 times the room. Rounding argument (f: the exact distance from the
    // chord's segment, convex and 1-Lipschitz; u = 2^-53; n <= 9 axes):
    //  1. chord_dist2 computes x^ = q - a - t^ d for some t^ in [0, 1] with |x^_k - x_k| <=
    //     6 u S per axis, so f(q) <= |x| <= sqrt(r^) (1 + 6 u) + 20 u S: each control point
    //     is within R (1 + 6 u) + 20 u S, R^2 = (1 - 2e-5) room^2.
    //  2. prove() splits once and proves both halves; their control points are convex
    //     combinations of these (f convex: within the same bound) computed with 3 roundings of
    //     at most u S each: 9 u S more.
    //  3. For any point, t^ is within D = 23 u |q - a| / |d| of the exact (clamped) minimiser,
    //     which adds at most sqrt(3) |d| D <= 240 u S to |x|; with step 1's 20 u S and the
    //     sum's rounding, chord_dist2's sqrt(r^) <= (f + 260 u S) (1 + 5 u).
    //  Together sqrt(r^) <= R (1 + 12 u) + 300 u S <= room (1 - 1e-5 + 13 u) + 300 u S, below
    //  room (1 - u) (which r2 = room * room is at least) whenever 300 u S < 1e-5 room.
    //  The halves' midpoint passes beyond_reach() on this chord for the same reason.
    // hull_scale: the largest |coordinate| of q's points.
    bool surely_near_chord(int c, const Hull& q, double hull_scale) const {
        const double r2 = room2(c);
        if (r2 < 0 || still_axes2 != 0 || dims != path.dims) return false;
        const double tight2 = r2 * kWholeHullRoom2Share;
        if (!(chord_dist2(c, q[3]) <= tight2 && chord_dist2(c, q[0]) <= tight2 &&
              chord_dist2(c, q[1]) <= tight2 && chord_dist2(c, q[2]) <= tight2))
            return false;
        const AxisArray &a = path.from[c], &d = path.dir[c];
        const int n = PathDims > 0 ? PathDims : path.dims;
        double scale = hull_scale;
        for (int k = 0; k < n; ++k) scale = std::max(scale, std::fabs(a[k]) + std::fabs(d[k]));
        return scale * scale <= kWholeHullScalePerRoom * kWholeHullScalePerRoom * r2;
    }

    // Tries the chord that held the previous piece first: the pieces follow the path in order.
    bool hull_near_path(const Hull& q, int& hint) const {
        for (int c = hint; c < path.count; ++c)
            if (hull_near_chord(c, q)) return hint = c, true;
        for (int c = hint - 1; c >= 0; --c)
            if (hull_near_chord(c, q)) return hint = c, true;
        return false;
    }

    // A curve point out of reach of every chord: no piece through it can be proved. The
    // points tried are the blend's halvings, nearest the corner: its chords first.
    bool beyond_reach(const AxisArray& p) const {
        auto near = [&](int c) {
            const double r2 = room2(c);
            return r2 >= 0 && chord_dist2(c, p) <= r2;
        };
        for (int c = path.corner_chord; c < path.count; ++c)
            if (near(c)) return false;
        for (int c = path.corner_chord - 1; c >= 0; --c)
            if (near(c)) return false;
        return true;
    }
};

// de Casteljau at u = 1/2: q becomes its left half. Dims as for Proof.
template <int Dims>
void split_half(Hull& q, Hull& right, int dims) {
    const int n = Dims > 0 ? Dims : dims;
    for (int k = 0; k < n; ++k) {
        double p01 = (q[0][k] + q[1][k]) / 2, p12 = (q[1][k] + q[2][k]) / 2,
               p23 = (q[2][k] + q[3][k]) / 2;
        double p012 = (p01 + p12) / 2, p123 = (p12 + p23) / 2;
        double mid = (p012 + p123) / 2;
        right[0][k] = mid, right[1][k] = p123, right[2][k] = p23, right[3][k] = q[3][k];
        q[1][k] = p01, q[2][k] = p012, q[3][k] = mid;
    }
}

// Only the first `dims` values of each point are ever read.
template <int Dims>
void copy_hull(Hull& to, const Hull& from, int dims) {
    const int n = Dims > 0 ? Dims : dims;
    for (int i = 0; i < 4; ++i)
        std::copy_n(from[i].begin(), n, to[i].begin());
}

// Depth-first over the halvings of `piece` (in `dims` dimensions): `pending` holds the right
// halves still to be proved.
template <int PathDims, int Dims>
bool prove(const Proof<PathDims, Dims>& proof, Hull& piece, int dims) {
    std::array<Hull, kMaxSplitDepth + 1> pending;
    std::array<int, kMaxSplitDepth + 1> pending_depth;
    // The first piece proved is the blend's start, on the move before the corner near it.
    int top = 0, depth = 0, hint = proof.path.corner_chord;
    for (;;) {
        // The whole blend spans both moves: start with its halves.
        if (depth > 0 && proof.hull_near_path(piece, hint)) {
            if (top == 0) return true;
            --top;
            copy_hull<Dims>(piece, pending[top], dims);
            depth = pending_depth[top];
            continue;
        }
        if (depth == kMaxSplitDepth) return false;
        split_half<Dims>(piece, pending[top], dims);
        if (proof.beyond_reach(piece[3])) return false;
        pending_depth[top++] = ++depth;
    }
}

// Whole::Try: first the whole piece on each chord (Proof::surely_near_chord), for a Bezier
// that may lie along one move, such as a lane change (shift_bezier_within): when that holds,
// prove() would succeed, so the result is the same, sooner.
enum class Whole : bool { Skip, Try };

template <int PathDims, int Dims = 0>
bool prove_hull(const CornerPath& path, double limit_mm, double still_axes2, Hull& piece, int dims,
                Whole whole) {
    const Proof<PathDims, Dims> proof{path, limit_mm, still_axes2, dims};
    if (whole == Whole::Try) {
        const int n = Dims > 0 ? Dims : dims;
        double scale = 0;
        for (const AxisArray& point : piece)
            for (int k = 0; k < n; ++k) scale = std::max(scale, std::fabs(point[k]));
        for (int c = 0; c < path.count; ++c)
            if (proof.surely_near_chord(c, piece, scale)) return true;
    }
    return prove(proof, piece, dims);
}

// bezier_within for a hull in the path's axes (then the blend's own), with still_axes2 the
// squared distance in the rest.
bool hull_within(const CornerPath& path, double limit_mm, double still_axes2, Hull& piece, int dims,
                 Whole whole = Whole::Skip) {
    switch (path.dims) {
        case 2:
            return dims == 2 ? prove_hull<2, 2>(path, limit_mm, still_axes2, piece, dims, whole)
                             : prove_hull<2>(path, limit_mm, still_axes2, piece, dims, whole);
        case 3:
            return dims == 3 ? prove_hull<3, 3>(path, limit_mm, still_axes2, piece, dims, whole)
                             : prove_hull<3>(path, limit_mm, still_axes2, piece, dims, whole);
        default:
            return prove_hull<0>(path, limit_mm, still_axes2, piece, dims, whole);
    }
}

}  // namespace

CornerPath corner_path(const Element& before, double before_mm, const Element& after,
                       double after_mm, double limit_mm) noexcept {
    CornerPath path;
    path.moving.fill(false);
    mark_moving_axes(before, path.moving);
    mark_moving_axes(after, path.moving);
    for (int k = 0; k < kAxes; ++k) {
        if (path.moving[k]) {
            path.axes[path.dims++] = k;
        } else {
            path.fixed[k] = before.end[k];
            path.still_axes[path.still_count++] = k;
        }
    }
    // A line's or an arc's points in an axis it does not move are origin + (+-0) terms, its
    // tangents +-0 (evaluate): equal to fixed and 0 when origin and end are.
    auto at_rest = [&](const Element& e) {
        if (e.kind != ElementKind::Line && e.kind != ElementKind::Arc) return false;
        for (int i = 0; i < path.still_count; ++i) {
            const int k = path.still_axes[i];
            if (e.origin[k] != path.fixed[k] || e.end[k] != path.fixed[k]) return false;
        }
        return true;
    };
    path.still_at_rest = at_rest(before) && at_rest(after);
    const double len = before.length_mm;
    add_chords(path, before, std::max(0.0, len - before_mm), len, len, before.end, limit_mm);
    path.corner_chord = path.count - 1;
    add_chords(path, after, 0, std::min(after_mm, after.length_mm), 0, before.end, limit_mm);
    return path;
}

bool bezier_within(const BezierPoints& bezier, const CornerPath& path, double limit_mm) noexcept {
    Hull piece;
    for (int j = 0; j < path.dims; ++j) {
        const int k = path.axes[j];
        piece[0][j] = bezier.p0[k], piece[1][j] = bezier.p1[k];
        piece[2][j] = bezier.p2[k], piece[3][j] = bezier.p3[k];
    }
    int dims = path.dims;
    double still_axes2 = 0;
    for (int k = 0; k < kAxes; ++k) {
        if (path.moving[k]) continue;
        const double x0 = bezier.p0[k];
        if (differs(bezier.p1[k], x0) | differs(bezier.p2[k], x0) | differs(bezier.p3[k], x0)) {
            piece[0][dims] = bezier.p0[k] - path.fixed[k];
            piece[1][dims] = bezier.p1[k] - path.fixed[k];
            piece[2][dims] = bezier.p2[k] - path.fixed[k];
            piece[3][dims] = bezier.p3[k] - path.fixed[k];
            ++dims;
        } else {
            still_axes2 += (x0 - path.fixed[k]) * (x0 - path.fixed[k]);
        }
    }
    return hull_within(path, limit_mm, still_axes2, piece, dims);
}

namespace {

bool piece_within(const BezierPoints& b, const CornerPath& path, double limit_mm, Whole whole) {
    // bezier_within would find every still axis still, at distance (p0 - fixed)^2 = 0.
    if (!path.still_at_rest) return bezier_within(b, path, limit_mm);
    Hull piece;
    for (int j = 0; j < path.dims; ++j) {
        const int k = path.axes[j];
        piece[0][j] = b.p0[k], piece[1][j] = b.p1[k];
        piece[2][j] = b.p2[k], piece[3][j] = b.p3[k];
    }
    return hull_within(path, limit_mm, 0, piece, path.dims, whole);
}

}  // namespace

bool corner_piece_within(const BezierPoints& b, const CornerPath& path, double limit_mm) noexcept {
    return piece_within(b, path, limit_mm, Whole::Skip);
}

bool corner_part_within(const BezierPoints& b, const CornerPath& path, double limit_mm) noexcept {
    return piece_within(b, path, limit_mm, Whole::Try);
}

namespace {

// corner_bezier_within and shift_bezier_within.
bool bezier_points_within(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                          const AxisArray& t2, double l_mm, const CornerPath& path,
                          double limit_mm, BezierPoints& out, Whole whole) {
    // At rest in the still axes (p0 = p3 = fixed, t1 = t2 = 0 there): d = p3 - p0 and t1 + t2
    // are +-0, which leave the sums bit for bit as they are; p1 = p0 + h t1 and p2 = p3 - h t2
    // equal p0 and p3, so bezier_within would count those axes as still, at distance
    // (p0 - fixed)^2 = 0.
    if (!path.still_at_rest) {
        std::optional<BezierPoints> b = corner_bezier_points(p0, t1, p3, t2, l_mm);
        if (!b || !bezier_within(*b, path, limit_mm)) return false;
        out = *b;
        return true;
    }
    double dd = 0, ds = 0, ss = 0;
    for (int j = 0; j < path.dims; ++j) {
        const int k = path.axes[j];
        double d = p3[k] - p0[k], sk = t1[k] + t2[k];
        dd += d * d, ds += d * sk, ss += sk * sk;
    }
    const double h = corner_bezier_h(dd, ds, ss, l_mm);
    if (!(h > 0)) return false;
    Hull piece;
    for (int j = 0; j < path.dims; ++j) {
        const int k = path.axes[j];
        piece[0][j] = p0[k], piece[1][j] = p0[k] + h * t1[k];
        piece[2][j] = p3[k] - h * t2[k], piece[3][j] = p3[k];
    }
    if (!hull_within(path, limit_mm, 0, piece, path.dims, whole)) return false;
    set_corner_bezier(p0, t1, p3, t2, h, out);
    return true;
}

}  // namespace

bool corner_bezier_within(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                          const AxisArray& t2, double l_mm, const CornerPath& path,
                          double limit_mm, BezierPoints& out) noexcept {
    return bezier_points_within(p0, t1, p3, t2, l_mm, path, limit_mm, out, Whole::Skip);
}

bool shift_bezier_within(const AxisArray& p0, const AxisArray& t1, const AxisArray& p3,
                         const AxisArray& t2, double l_mm, const CornerPath& path, double limit_mm,
                         BezierPoints& out) noexcept {
    return bezier_points_within(p0, t1, p3, t2, l_mm, path, limit_mm, out, Whole::Try);
}

}  // namespace motion
