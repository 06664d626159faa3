// The acceleration-aware lower bound (accel_bound.hpp). The proof is in docs/benchmarks.md ("The
// acceleration-aware lower bound"); each function below names the step it implements.
//
// Model (the path-distance contract): moves S_1..S_n from vertex c_{i-1} to c_i; the tool q(t)
// has |q'_k| <= V_k and |q''_k| <= A_k, starts at rest at c_0 and ends at rest at c_n, and there
// are instants 0 = t_0 <= t_1 <= ... <= t_n = T such that during [t_{i-1}, t_i] the tool is
// within P_i of S_i (as a point set) and, on a feed move, no faster than its feed. So at t_v the
// tool is in the corner region R_v = N(S_v) n N(S_{v+1}) (within P of both moves), not
// necessarily within P of c_v. The pieces [t_{i-1}, t_i] are disjoint in time, so lower bounds
// on them add up. Every place the tool's position at t_v is needed, the proof uses only the
// support of R_v, h_v(d) >= max over x in R_v of d . (x - c_v) (region_support).
#include "accel_bound.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "motion/geometry.hpp"

namespace motion::bench {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr int kDim = 3;  // X Y Z
using Vec3 = std::array<double, kDim>;
// Offset grid for the chained line pieces (see the DP in accel_lower_bound): cells per vertex.
constexpr int kCells = 24;
// Arc pieces per full turn when an arc is cut against the reach box (extent()).
constexpr int kArcPiecesPerTurn = 256;
// Window half-angles tried at an arc's extreme point.
constexpr int kWindowSteps = 48;
// Rounds of shrinking the reach with the component bound found so far (component_bound).
constexpr int kReachRounds = 4;
// Rounds of the searches for a good split in region_support (any split is sound).
constexpr int kGoldenRounds = 60;
constexpr int kPatternRounds = 30;

double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double norm(const Vec3& a) {
    return std::sqrt(dot(a, a));
}
Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Vec3 add(const Vec3& a, const Vec3& b) {
    return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
}
Vec3 scale(const Vec3& a, double f) {
    return {a[0] * f, a[1] * f, a[2] * f};
}
Vec3 neg(const Vec3& a) {
    return {-a[0], -a[1], -a[2]};
}
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 xyz(const AxisArray& a) {
    return {a[0], a[1], a[2]};
}
Vec3 unit_or_zero(const Vec3& a) {
    double n = norm(a);
    if (n < 1e-12) return {0, 0, 0};
    return {a[0] / n, a[1] / n, a[2] / n};
}
Vec3 axis(int k) {
    Vec3 e{0, 0, 0};
    e[k] = 1;
    return e;
}

// Largest d . q'' (resp. d . q') the axis box allows: sum_k A_k |d_k|.
double box_support(const Vec3& d, const AxisArray& per_axis) {
    double s = 0;
    for (int k = 0; k < kDim; ++k) s += per_axis[k] * std::fabs(d[k]);
    return s;
}

// Minimum time to cover distance d_mm in 1-D with |v| <= vmax, |acc| <= acc, speed at most v0 at
// the start and at most v1 at the end (the end speeds are upper bounds, not prescribed).
double min_time_1d(double d_mm, double v0, double v1, double vmax, double acc) {
    if (d_mm <= 0) return 0;
    v0 = std::min(v0, vmax);
    v1 = std::min(v1, vmax);
    if (v0 > v1 && (v0 * v0 - v1 * v1) / (2 * acc) >= d_mm)  // start slower, brake all the way
        return (std::sqrt(v1 * v1 + 2 * acc * d_mm) - v1) / acc;
    if (v1 > v0 && (v1 * v1 - v0 * v0) / (2 * acc) >= d_mm)  // accelerate all the way
        return (std::sqrt(v0 * v0 + 2 * acc * d_mm) - v0) / acc;
    double peak2 = (2 * acc * d_mm + v0 * v0 + v1 * v1) / 2;
    if (peak2 <= vmax * vmax) return (2 * std::sqrt(peak2) - v0 - v1) / acc;
    double ramps_mm = (2 * vmax * vmax - v0 * v0 - v1 * v1) / (2 * acc);
    return (2 * vmax - v0 - v1) / acc + (d_mm - ramps_mm) / vmax;
}

// Rise by h and stop (or stop and fall by h) in 1-D: the time an axis needs to turn round.
double turn_time_1d(double h_mm, double vmax, double acc) {
    if (h_mm <= 0) return 0;
    if (h_mm <= vmax * vmax / (2 * acc)) return std::sqrt(2 * h_mm / acc);
    return h_mm / vmax + vmax / (2 * acc);
}

struct Move {
    Element e;
    double length_mm = 0;
    double feed_mm_s = 0;      // 0 = rapid
    double corner_tol_mm = 0;  // G64 P of the corner at this move's end (0 = exact path)
    // P of the contract while the tool is assigned to this move: the larger of the tolerances
    // of the corners at its two ends (a blend at either end may use its own P on this move).
    double tol_mm = 0;
    bool stop_after = false;  // G09 or a dwell: at rest at its end
    bool arc = false;
    bool helix = false;  // an arc with off-plane travel
    Vec3 start{}, end{}, u_start{}, u_end{};
    // Arcs: in-plane unit tangents (walk direction) and unit radial directions at both ends.
    Vec3 u_start_plane{}, u_end_plane{}, radial_start{}, radial_end{};
};

// Point of a move at fraction f of it (0 = start, 1 = end).
Vec3 point_at_fraction(const Move& m, double f) {
    if (f <= 0) return m.start;
    if (f >= 1) return m.end;
    if (!m.arc) return add(m.start, scale(sub(m.end, m.start), f));
    return xyz(point_at(m.e, f * m.length_mm));
}

// Exact max over fractions [f0, f1] of the move of a . (p(f) - c). For an arc this is a
// sinusoid in the angle plus the helix's linear term: its ends and stationary points.
double max_dot(const Move& m, const Vec3& a, const Vec3& c, double f0, double f1) {
    double best = std::max(dot(a, sub(point_at_fraction(m, f0), c)),
                           dot(a, sub(point_at_fraction(m, f1), c)));
    if (!m.arc || f1 <= f0) return best;
    const Element& e = m.e;
    double alpha = dot(a, xyz(e.a)), beta = dot(a, xyz(e.b)), lin = dot(a, xyz(e.c));
    double amp = std::hypot(alpha, beta);
    double k = e.sweep_rad;  // d theta / d f
    if (amp < 1e-15) return best;
    // d/df: r k amp sin(psi - theta) + lin = 0.
    double ratio = -lin / (e.radius_mm * k * amp);
    if (std::fabs(ratio) > 1) return best;
    double psi = std::atan2(beta, alpha), as = std::asin(ratio);
    double th0 = e.theta0_rad + k * f0, th1 = e.theta0_rad + k * f1;
    double lo = std::min(th0, th1), hi = std::max(th0, th1);
    for (double base : {psi - as, psi - kPi + as}) {
        for (double j = std::ceil((lo - base) / (2 * kPi)); base + 2 * kPi * j <= hi; j += 1) {
            double f = (base + 2 * kPi * j - e.theta0_rad) / k;
            if (f > f0 && f < f1) best = std::max(best, dot(a, sub(point_at_fraction(m, f), c)));
        }
    }
    return best;
}

// Parts of a move that touches the corner c at one end (at_end: the move ends at c), as ranges
// of the move's fraction, holding every point whose distance from c lies in [lo_mm, hi_mm] (a
// superset is fine: these ranges only ever widen a maximum or narrow a distance).
struct Spans {
    std::array<std::pair<double, double>, 2> range{};
    int count = 0;
    void push(double f0, double f1) {
        f0 = std::clamp(f0, 0.0, 1.0), f1 = std::clamp(f1, 0.0, 1.0);
        if (f0 <= f1) range[count++] = {f0, f1};
    }
};

Spans spans_within(const Move& m, bool at_end, double lo_mm, double hi_mm) {
    Spans sp;
    auto from_c = [&](double g0, double g1) {  // fractions measured from c's end
        if (at_end)
            sp.push(1 - g1, 1 - g0);
        else
            sp.push(g0, g1);
    };
    lo_mm = std::max(lo_mm, 0.0);
    if (hi_mm < lo_mm) return sp;
    if (!m.arc) {
        if (lo_mm <= m.length_mm) from_c(lo_mm / m.length_mm, hi_mm / m.length_mm);
        return sp;
    }
    double sweep = std::fabs(m.e.sweep_rad), r = m.e.radius_mm;
    if (sweep > 2 * kPi + 1e-9) {  // more than one turn: no localisation
        sp.push(0, 1);
        return sp;
    }
    // The in-plane chord from c at angle phi along the arc is 2 r sin(phi / 2), and the distance
    // is at least the chord (equal without a helix), so the chord is at most hi and, without a
    // helix, at least lo.
    auto angle_of = [&](double chord) { return 2 * std::asin(std::min(1.0, chord / (2 * r))); };
    double a_lo = m.helix ? 0 : angle_of(lo_mm), a_hi = angle_of(hi_mm);
    from_c(a_lo / sweep, a_hi / sweep);
    if (2 * kPi - a_hi < sweep) from_c((2 * kPi - a_hi) / sweep, (2 * kPi - a_lo) / sweep);
    return sp;
}

double max_dot_spans(const Move& m, const Vec3& a, const Vec3& c, const Spans& sp) {
    double best = -kInf;
    for (int i = 0; i < sp.count; ++i)
        best = std::max(best, max_dot(m, a, c, sp.range[i].first, sp.range[i].second));
    return best;
}

// Chords of the spans: pieces of at most 2 pi / kArcPiecesPerTurn of an arc lie within their
// sagitta of the chord (the helix's travel is linear along the piece, so the chord keeps it).
struct Chord {
    Vec3 a, b;
    double margin_mm;
};

void chords_of(const Move& m, const Spans& sp, std::vector<Chord>& out) {
    for (int i = 0; i < sp.count; ++i) {
        auto [f0, f1] = sp.range[i];
        if (!m.arc) {
            out.push_back({point_at_fraction(m, f0), point_at_fraction(m, f1), 0});
            continue;
        }
        double ang = std::fabs(m.e.sweep_rad) * (f1 - f0);
        int pieces = std::max(1, int(std::ceil(ang / (2 * kPi) * kArcPiecesPerTurn)));
        double sag = m.e.radius_mm * (1 - std::cos(ang / pieces / 2));
        for (int j = 0; j < pieces; ++j)
            out.push_back({point_at_fraction(m, f0 + (f1 - f0) * j / pieces),
                           point_at_fraction(m, f0 + (f1 - f0) * (j + 1) / pieces), sag});
    }
}

// Distance between segments [p1, q1] and [p2, q2] (closest points by clamped parameters).
double segment_distance(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
    Vec3 d1 = sub(q1, p1), d2 = sub(q2, p2), r = sub(p1, p2);
    double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s = 0, t = 0;
    if (a <= 1e-30 && e <= 1e-30) return norm(r);
    if (a <= 1e-30) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        double c = dot(d1, r);
        if (e <= 1e-30) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            double b = dot(d1, d2), denom = a * e - b * b;
            s = denom > 1e-30 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0, s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1) {
                t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return norm(sub(add(p1, scale(d1, s)), add(p2, scale(d2, t))));
}

// The corner region R at the vertex c between moves `in` and `out` is the connected part that
// holds c of the set of points within in.tol of `in` and within out.tol of `out` (the tool goes
// from one move to the next through the corner, not through some other place where the two
// moves come close, such as a rapid crossing the circle that follows it). If no point at
// distance rho from c is within the tolerances of both moves, R lies inside the ball of radius
// rho (it is connected and holds c), and only the parts of the moves within rho + P of c matter.
// The test: the parts of the two moves at distances [rho - P, rho + P] from c are more than
// P_in + P_out apart. Returns the smallest rho of a short list that passes, or infinity.
double corner_radius(const Move& in, const Move& out, const Vec3& c) {
    double tol = std::max(in.tol_mm, out.tol_mm), both = in.tol_mm + out.tol_mm;
    if (tol <= 0) tol = 1e-9;
    std::vector<Chord> ci, co;
    for (double mult : {3.0, 5.0, 10.0, 30.0, 100.0, 1000.0}) {
        double rho = mult * tol;
        ci.clear(), co.clear();
        chords_of(in, spans_within(in, true, rho - tol, rho + tol), ci);
        chords_of(out, spans_within(out, false, rho - tol, rho + tol), co);
        bool apart = true;
        for (const Chord& a : ci) {
            for (const Chord& b : co)
                if (segment_distance(a.a, a.b, b.a, b.b) - a.margin_mm - b.margin_mm <= both) {
                    apart = false;
                    break;
                }
            if (!apart) break;
        }
        if (apart) return rho;
    }
    return kInf;
}

// The support of the corner region: an upper bound on max d . (x - c) over x in R. For any
// split d = a + b, x = p1 + e1 = p2 + e2 (p1 on `in`, p2 on `out`, both within rho + P of c,
// |e1|, |e2| within the tolerances) gives d . (x - c) = a . (p1 - c) + a . e1 + b . (p2 - c) +
// b . e2, so
//   h(d) <= max_in a . (p - c) + P_in |a| + max_out b . (p - c) + P_out |b|
// for every a. Any a is sound; the searches only look for a small value. With a . u_in >= 0 and
// b . u_out <= 0 the path terms vanish for lines, which gives P |d| when d . u_in >= 0 or
// d . u_out <= 0, and more otherwise (sqrt(2) P along the inner diagonal of a right angle).
struct CornerParts {
    const Move* in;
    const Move* out;
    Vec3 c;
    Spans in_near, out_near;  // the parts within rho + P of c
};

double split_cost(const CornerParts& cp, const Vec3& d, const Vec3& a) {
    Vec3 b = sub(d, a);
    return max_dot_spans(*cp.in, a, cp.c, cp.in_near) + cp.in->tol_mm * norm(a) +
           max_dot_spans(*cp.out, b, cp.c, cp.out_near) + cp.out->tol_mm * norm(b);
}

double region_support(const CornerParts& cp, const Vec3& d_any) {
    double len = norm(d_any);
    if (len < 1e-15) return 0;
    Vec3 d = scale(d_any, 1 / len);
    Vec3 best_a{0, 0, 0};
    double best = split_cost(cp, d, best_a);
    auto consider = [&](const Vec3& a) {
        double v = split_cost(cp, d, a);
        if (v < best) best = v, best_a = a;
    };
    consider(d);
    // The region holds the disc of the smaller tolerance about c, so no split can beat that.
    if (best <= std::min(cp.in->tol_mm, cp.out->tol_mm) * (1 + 1e-12)) return best * len;
    // Both path terms zero for lines: a . u1 = 0 and (d - a) . u2 = 0, a line of a's.
    Vec3 u1 = cp.in->u_end, u2 = cp.out->u_start;
    Vec3 n = cross(u1, u2);
    double s2 = dot(n, n);
    if (s2 > 1e-12) {
        double cs = dot(u1, u2);
        double y = dot(d, u2) / s2, x = -y * cs;
        Vec3 a0 = add(scale(u1, x), scale(u2, y));
        Vec3 nn = scale(n, 1 / std::sqrt(s2));
        double lo = -4, hi = 4;  // golden section on the convex cost along the line
        const double g = (std::sqrt(5.0) - 1) / 2;
        for (int i = 0; i < kGoldenRounds; ++i) {
            double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
            if (split_cost(cp, d, add(a0, scale(nn, m1))) <
                split_cost(cp, d, add(a0, scale(nn, m2))))
                hi = m2;
            else
                lo = m1;
        }
        consider(add(a0, scale(nn, (lo + hi) / 2)));
    }
    // A few rounds of pattern search from the best split so far (arcs, short moves, 3-D).
    double step = 0.25;
    for (int round = 0; round < kPatternRounds; ++round) {
        bool moved = false;
        for (int k = 0; k < kDim; ++k)
            for (double sgn : {-1.0, 1.0}) {
                Vec3 a = best_a;
                a[k] += sgn * step;
                double before = best;
                consider(a);
                moved = moved || best < before;
            }
        if (!moved) step /= 2;
    }
    return best * len;
}

// Everything the proof needs to know about one vertex: its point and the support of its
// corner region. At the program's ends the tool is exactly at the point (h = 0).
struct Vertex {
    Vec3 c{};
    bool ends = true;  // the program's start or end
    CornerParts parts{};
    double h(const Vec3& d) const {
        if (ends) return 0;
        return region_support(parts, d);
    }
    // Largest |x_k - c_k| over the region.
    Vec3 spread() const {
        Vec3 r{};
        for (int k = 0; k < kDim; ++k) r[k] = std::max(h(axis(k)), h(neg(axis(k))));
        return r;
    }
};

// How deep into a move the tool can be at the instant t of its start vertex (entry) and how
// early it can leave it at its end vertex (exit), measured along the move, plus whether its
// angle about an arc's centre is defined there. Lines: distances along u. Arcs: angles.
struct Depths {
    double in_start = 0;    // lines: h_start(u)    (how far along u the tool may already be)
    double back_start = 0;  // lines: h_start(-u)
    double in_end = 0;      // lines: h_end(-u)     (how far short of the end it may leave)
    double back_end = 0;    // lines: h_end(u)
    double angle_start = 0, angle_end = 0;  // arcs: the same as angles about the centre
    bool angles_ok = false;                 // arcs: both regions clear of the centre
};

// Upper bound on the angle alpha of a tool point whose tangent coordinate is at most z, at an
// in-plane distance in [r - P, r + P] from the centre, with cos(alpha) > 0: sin(alpha) = z'/rho.
double angle_bound(double z, double r, double tol) {
    if (z >= 0) return z >= r - tol ? kPi / 2 : std::asin(z / (r - tol));
    return std::asin(std::max(-1.0, z / (r + tol)));
}

Depths depths_of(const Move& m, const Vertex& vs, const Vertex& ve) {
    Depths d;
    if (!m.arc) {
        d.in_start = vs.h(m.u_start);
        d.back_start = vs.h(neg(m.u_start));
        d.in_end = ve.h(neg(m.u_end));
        d.back_end = ve.h(m.u_end);
        return d;
    }
    double r = m.e.radius_mm, tol = m.tol_mm;
    // The angle is measured about the centre in the plane; it is defined while the region does
    // not reach across the centre (radial coordinate above -r). The region is within tol of
    // this arc, so its in-plane distance from the centre is in [r - tol, r + tol].
    // The tool's angle can only be followed without a whole-turn ambiguity if it cannot wrap
    // round: the angles within P of the arc, [-asin(P / r), sweep + asin(P / r)], must leave a
    // gap, and near each end the region may only hold points near that end, not the other
    // (single span: a full or nearly closed circle can otherwise be skipped, the tool staying
    // where the circle starts and ends).
    auto one_end_only = [&](const Vertex& vx, bool at_start) {
        if (vx.ends) return true;
        return (at_start ? vx.parts.out_near : vx.parts.in_near).count == 1;
    };
    double sweep = std::fabs(m.e.sweep_rad);
    d.angles_ok = r > tol && sweep + 2 * std::asin(std::min(1.0, tol / r)) < 2 * kPi &&
                  one_end_only(vs, true) && one_end_only(ve, false) &&
                  vs.h(neg(m.radial_start)) < r && ve.h(neg(m.radial_end)) < r;
    if (!d.angles_ok) return d;
    d.angle_start = std::max(0.0, angle_bound(vs.h(m.u_start_plane), r, tol));
    d.angle_end = std::max(0.0, angle_bound(ve.h(neg(m.u_end_plane)), r, tol));
    return d;
}

// What the tool can reach while a velocity component is braked from the instant t_v: it stays
// in the box |q_k - c_k| <= box_mm[k] (the region's spread plus V_k times the braking time), for
// at most time_s.
struct Reach {
    Vec3 box_mm{};
    double time_s = 0;
};

struct Context {
    const std::vector<Move>& moves;
    const std::vector<Vertex>& vertex;
    const std::vector<Depths>& depth;
    const std::vector<Vec3>& spread;
    const AxisLimits& lim;
};

// Interval of lambda in [0, len] with |p0 + lambda u - c|_k <= box_k for every axis (may be
// empty: lo > hi).
std::pair<double, double> box_interval(const Vec3& p0, const Vec3& u, double len, const Vec3& c,
                                       const Vec3& box) {
    double lo = 0, hi = len;
    for (int k = 0; k < kDim; ++k) {
        double a = p0[k] - c[k];
        if (std::fabs(u[k]) < 1e-15) {
            if (std::fabs(a) > box[k]) return {1, 0};
            continue;
        }
        double l1 = (-box[k] - a) / u[k], l2 = (box[k] - a) / u[k];
        lo = std::max(lo, std::min(l1, l2));
        hi = std::min(hi, std::max(l1, l2));
    }
    return {lo, hi};
}

bool in_box(const Vec3& p, const Vec3& c, const Vec3& box) {
    for (int k = 0; k < kDim; ++k)
        if (std::fabs(p[k] - c[k]) > box[k]) return false;
    return true;
}

// Step 1's extent: an upper bound on d . (q(tau) - c_v) at the instant tau when a braked
// component has stopped, forward (tau > t_v) or backward (tau < t_v) in time. At tau the tool is
// assigned to some move j after v (before v), within P_j of a point p of S_j, and in the reach
// box, so p lies in the box grown by P_j. Move j + 1 can only be reached if the tool finished
// move j within the braking time: it then passed within P_j of every point of S_j beyond the
// entry depth and short of the exit depth (the tool's coordinate along a line, its angle about
// an arc's centre, moves continuously between them, and at equal coordinate the distance to that
// point is at most the distance to the move), so all of those lie in the grown box, and it
// covered that stretch at no more than its speed bound. The walk stops at the first move for
// which either fails. On the move reached, the tool's coordinate is at most the entry depth plus
// the speed times the time left, which cuts the candidates further.
double extent(const Context& cx, std::size_t v, const Vec3& d, bool forward, const Reach& reach) {
    const Vec3& c = cx.vertex[v].c;
    double best = -kInf;
    double time_left_s = reach.time_s;
    std::size_t n = cx.moves.size();
    for (std::size_t step = 0;; ++step) {
        std::size_t j;
        if (forward) {
            if (v + step >= n) break;
            j = v + step;
        } else {
            if (step >= v) break;
            j = v - 1 - step;
        }
        const Move& m = cx.moves[j];
        const Depths& dp = cx.depth[j];
        Vec3 box{};
        for (int k = 0; k < kDim; ++k) box[k] = reach.box_mm[k] + m.tol_mm;
        if (!m.arc) {
            Vec3 p0 = forward ? m.start : m.end;
            Vec3 u = forward ? m.u_start : neg(m.u_start);
            double entry = forward ? dp.in_start : dp.in_end;
            double exit_short = forward ? dp.in_end : dp.in_start;
            double feed = m.feed_mm_s > 0 ? m.feed_mm_s : kInf;
            double speed = std::min(feed, box_support(u, cx.lim.vel_mm_s));
            double reach_mm = std::clamp(entry + speed * time_left_s, 0.0, m.length_mm);
            auto [blo, bhi] = box_interval(p0, u, m.length_mm, c, box);
            double lo = blo, hi = std::min(bhi, reach_mm);
            if (lo <= hi)
                best = std::max({best, dot(d, sub(add(p0, scale(u, lo)), c)) + m.tol_mm,
                                 dot(d, sub(add(p0, scale(u, hi)), c)) + m.tol_mm});
            double g_lo = std::max(0.0, entry),
                   g_hi = std::min(m.length_mm, m.length_mm - exit_short);
            if (g_lo <= g_hi && (blo > bhi || g_lo < blo || g_hi > bhi)) break;
            time_left_s -= std::max(0.0, m.length_mm - entry - exit_short) / speed;
            if (time_left_s < 0) break;
            continue;
        }
        // Arc, walked from its entry end: fraction f of the walk is fraction 1 - f of the move
        // backwards.
        auto frac = [&](double walk_f) { return forward ? walk_f : 1 - walk_f; };
        double sweep = std::fabs(m.e.sweep_rad), r = m.e.radius_mm;
        double reach_f = 1;  // how far along the walk the candidates go
        double entry = 0, exit_short = 0;
        double feed = m.feed_mm_s > 0 ? m.feed_mm_s : kInf;
        double plane_v = 0;
        for (int k = 0; k < kDim; ++k) {
            double in_plane = std::hypot(m.e.a[k], m.e.b[k]);
            plane_v += cx.lim.vel_mm_s[k] * in_plane * cx.lim.vel_mm_s[k] * in_plane;
        }
        double speed = std::min(feed, std::sqrt(plane_v));
        // The in-plane angle argument holds on a helix too, but the nearest point at the tool's
        // angle is in-plane only: a helix's stretch is not taken as passed in 3-D.
        bool known = dp.angles_ok && !m.helix;
        if (known) {
            entry = forward ? dp.angle_start : dp.angle_end;
            exit_short = forward ? dp.angle_end : dp.angle_start;
            // In-plane path >= (r - P) x angle, in-plane speed <= speed.
            double reach_angle = entry + speed * time_left_s / (r - m.tol_mm);
            reach_f = std::clamp(reach_angle / sweep, 0.0, 1.0);
        }
        int pieces = std::max(1, int(std::ceil(sweep * reach_f / (2 * kPi) * kArcPiecesPerTurn)));
        double step_rad = sweep * reach_f / pieces;
        double sag = r * (1 - std::cos(step_rad / 2));
        Vec3 sag_box{};
        for (int k = 0; k < kDim; ++k) sag_box[k] = box[k] + sag;
        for (int i = 0; i < pieces; ++i) {
            double fa = reach_f * i / pieces, fb = reach_f * (i + 1) / pieces;
            Vec3 pa = point_at_fraction(m, frac(fa)), pb = point_at_fraction(m, frac(fb));
            // The piece lies within the sagitta of its chord: skip it only if that misses the box.
            bool may = true;
            for (int k = 0; k < kDim; ++k)
                if (std::min(pa[k], pb[k]) - c[k] > sag_box[k] ||
                    std::max(pa[k], pb[k]) - c[k] < -sag_box[k])
                    may = false;
            if (!may) continue;
            double f0 = std::min(frac(fa), frac(fb)), f1 = std::max(frac(fa), frac(fb));
            best = std::max(best, max_dot(m, d, c, f0, f1) + m.tol_mm);
        }
        // If the tool's angle is outside the arc's span, its nearest point is an end point.
        Vec3 exit_point = forward ? m.end : m.start;
        if (in_box(exit_point, c, box))
            best = std::max(best, dot(d, sub(exit_point, c)) + m.tol_mm);
        if (!known) continue;  // nothing is known to be passed: the walk goes on
        double g_lo = entry / sweep, g_hi = 1 - exit_short / sweep;
        bool left = false;
        if (g_lo <= g_hi) {
            int checks =
                std::max(2, int(std::ceil((g_hi - g_lo) * sweep / (2 * kPi) * kArcPiecesPerTurn)));
            for (int i = 0; i <= checks && !left; ++i)
                left =
                    !in_box(point_at_fraction(m, frac(g_lo + (g_hi - g_lo) * i / checks)), c, box);
        }
        if (left) break;
        time_left_s -= (r - m.tol_mm) * std::max(0.0, sweep - entry - exit_short) / speed;
        if (time_left_s < 0) break;
    }
    return best;
}

// Upper bound on |d . q'(t_v)| for one unit direction d (either sign). With w = d . q'(t_v) > 0,
// y = d . q rises by at least w^2 / 2A_d before it stops at tau = t_v + w / A_d (its rate falls by
// at most A_d = sum_k A_k |d_k|; the tool is at rest at T, so tau <= T), so
//   w^2 / 2A_d <= [d . (q(tau) - c)] - [d . (q(t_v) - c)] <= E_fwd(d) + h_v(-d),
// and backwards in time likewise with the earlier path: w^2 / 2A_d <= E_back(-d) + h_v(d).
// Braking w takes w / A_d, so a bound on w shrinks the reach (axis k moves at most V_k w / A_d
// meanwhile), which can lower the bound again: a few rounds, each sound given the last.
double component_bound(const Context& cx, std::size_t v, const Vec3& d) {
    double a_d = box_support(d, cx.lim.acc_mm_s2);
    const Vertex& vx = cx.vertex[v];
    auto one_sign = [&](const Vec3& dir) {
        Vec3 back = neg(dir);
        double slack_fwd = vx.h(back), slack_back = vx.h(dir);
        double w = box_support(dir, cx.lim.vel_mm_s);
        for (int round = 0; round < kReachRounds; ++round) {
            Reach reach;
            reach.time_s = w / a_d;
            for (int k = 0; k < kDim; ++k)
                reach.box_mm[k] = cx.spread[v][k] + cx.lim.vel_mm_s[k] * reach.time_s;
            double e = std::min(extent(cx, v, dir, true, reach) + slack_fwd,
                                extent(cx, v, back, false, reach) + slack_back);
            double w_next = std::sqrt(2 * a_d * std::max(0.0, e));
            if (w_next >= w) break;
            w = w_next;
        }
        return w;
    };
    return std::max(one_sign(d), one_sign(neg(d)));
}

// Speed bounds at vertex v (between moves v-1 and v; 0 and n are the program's ends): on |q'|
// (for arcs, which are timed along the tool's path) and on the components of q' along the
// incoming and the outgoing tangent (for lines, which are timed along their direction).
struct CornerCaps {
    double speed = kInf, along_in = kInf, along_out = kInf;
};

CornerCaps corner_caps(const Context& cx, std::size_t v, int& capped, int& stops) {
    std::size_t n = cx.moves.size();
    CornerCaps stop{0, 0, 0};
    if (v == 0 || v == n) return ++stops, stop;
    const Move& in = cx.moves[v - 1];
    if (in.stop_after) return ++stops, stop;
    Vec3 u1 = in.u_end, u2 = cx.moves[v].u_start;
    double cos_turn = dot(u1, u2);
    if (cos_turn > 1 - 1e-12) return {};              // tangent
    if (in.corner_tol_mm <= 0) return ++stops, stop;  // G61: a kink on the exact path is a stop
    Vec3 e2 = unit_or_zero(sub(u2, scale(u1, cos_turn)));
    if (norm(e2) == 0)
        e2 = unit_or_zero(cross(u1, std::fabs(u1[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    Vec3 e3 = cross(u1, e2);
    CornerCaps caps;
    double sum2 = 0;
    for (const Vec3& d : {u1, e2, e3}) {
        double b = component_bound(cx, v, d);
        sum2 += b * b;
    }
    // The axes' own components bound those along u1 and u2 too (|u . q'| <= sum_k |u_k| |q'_k|),
    // which is tighter where a line is nearly along an axis whose path stops there (the end of a
    // sine row: u1 is 5 degrees off X, and the path goes on along u1 only by that skew).
    Vec3 axis_caps, speed_axes{0, 0, 0};
    for (int k = 0; k < kDim; ++k) {
        axis_caps[k] = component_bound(cx, v, axis(k));
        speed_axes[k] = axis_caps[k] * axis_caps[k];
    }
    caps.speed =
        std::min(std::sqrt(sum2), std::sqrt(speed_axes[0] + speed_axes[1] + speed_axes[2]));
    auto via_axes = [&](const Vec3& u) {
        return std::fabs(u[0]) * axis_caps[0] + std::fabs(u[1]) * axis_caps[1] +
               std::fabs(u[2]) * axis_caps[2];
    };
    caps.along_in = std::min(component_bound(cx, v, u1), via_axes(u1));
    caps.along_out = std::min(component_bound(cx, v, u2), via_axes(u2));
    ++capped;
    return caps;
}

double feed_cap(const Move& m, const Vec3& dir, const AxisLimits& lim) {
    double v = box_support(dir, lim.vel_mm_s);
    return m.feed_mm_s > 0 ? std::min(m.feed_mm_s, v) : v;
}

// Step 3, an arc piece: the larger of (a) the in-plane path the tool must cover, (r - P) times
// the angle from its entry to its exit bound, at the feed from its corner speed bounds and (b)
// that path at the feed plus, at each extreme point of a plane axis whose window fits inside the
// angles the tool is known to pass, the extra time that axis needs to turn round.
double arc_time(const Move& m, const Depths& dp, double cap_in, double cap_out,
                const AxisLimits& lim, int& windows) {
    if (!dp.angles_ok) return 0;
    double r = m.e.radius_mm, tol = m.tol_mm;
    double sweep = std::fabs(m.e.sweep_rad);
    double inner = r - tol;
    double covered = sweep - dp.angle_start - dp.angle_end;  // angle the tool surely turns
    if (covered <= 0) return 0;
    Vec3 u = xyz(m.e.a), w = xyz(m.e.b);
    double plane_vmax = 0, plane_acc = 0;
    for (int k = 0; k < kDim; ++k) {
        double in_plane = std::hypot(u[k], w[k]);
        plane_vmax += lim.vel_mm_s[k] * in_plane * lim.vel_mm_s[k] * in_plane;
        plane_acc += lim.acc_mm_s2[k] * in_plane * lim.acc_mm_s2[k] * in_plane;
    }
    double feed =
        m.feed_mm_s > 0 ? std::min(m.feed_mm_s, std::sqrt(plane_vmax)) : std::sqrt(plane_vmax);
    double full = min_time_1d(inner * covered, cap_in, cap_out, feed, std::sqrt(plane_acc));

    // Extreme points: axis k's coordinate is r m_k cos(theta - phi_k) about the centre.
    double th0 = m.e.theta0_rad, sgn = m.e.sweep_rad >= 0 ? 1 : -1;
    double extra_s = 0;
    for (int k = 0; k < kDim; ++k) {
        double mk = std::hypot(u[k], w[k]);
        if (mk < 1e-9) continue;
        double phi = std::atan2(w[k], u[k]);
        // Angles phi + j pi inside the sweep, measured from the start along the sweep.
        double first = std::fmod(sgn * (phi - th0), kPi);
        if (first < 0) first += kPi;
        for (double at = first; at < sweep; at += kPi) {
            // The window's three points must lie in the stretch the tool surely passes.
            double half_max = std::min({kPi / 4, at - dp.angle_start, sweep - dp.angle_end - at});
            if (half_max <= 0) continue;
            double best_gain = 0;
            for (int i = 1; i <= kWindowSteps; ++i) {
                double half = half_max * i / kWindowSteps;
                double h = r * mk * (1 - std::cos(half)) - 2 * tol;
                double turn = 2 * turn_time_1d(h, lim.vel_mm_s[k], lim.acc_mm_s2[k]);
                double at_feed = inner * 2 * half / feed;
                best_gain = std::max(best_gain, turn - at_feed);
            }
            if (best_gain <= 0) continue;
            extra_s += best_gain;
            ++windows;
        }
    }
    if (extra_s == 0) return full;
    return std::max(full, inner * covered / feed + extra_s);
}

// Carries the component caps of step 1 along chains of lines (a backward and a forward pass),
// so that a run of short moves into a corner must slow down before its last move. During line
// v (from vertex v to v + 1, direction u, length L) the tool stays within P of it, so y = u . q
// is at most u . c_v + L + P, and at t_v it is at least u . c_v - h_v(-u). If y' = w > B at t_v
// and |y'| <= B at t_{v+1}, y' first falls to B after y rose by (w^2 - B^2) / 2A_u, so
// w^2 <= B^2 + 2 A_u (L + P + h_v(-u)); for y' = -w, w^2 <= B^2 + 2 A_u (P + h_v(u)). The same
// forwards with h_{v+1}. At a vertex the components along the two lines' directions belong to
// one velocity, so they differ by at most (u_v - u_{v+1}) . q' <= sum_k V_k |u_v,k - u_v+1,k|.
// Arcs cut the chain (their caps stay as step 1 gives them).
void propagate_caps(const std::vector<Move>& moves, const std::vector<Depths>& depth,
                    const AxisLimits& lim, std::vector<CornerCaps>& cap) {
    std::size_t n = moves.size();
    auto acc = [&](std::size_t i) { return box_support(moves[i].u_start, lim.acc_mm_s2); };
    auto skew = [&](std::size_t v) {  // vertex v joins lines v - 1 and v
        return box_support(sub(moves[v - 1].u_end, moves[v].u_start), lim.vel_mm_s);
    };
    auto grow = [](double b, double a, double room) { return std::sqrt(b * b + 2 * a * room); };
    for (std::size_t v = n - 1; v >= 1; --v) {
        if (moves[v].arc || moves[v - 1].arc) continue;
        const Move& m = moves[v];
        const Depths& d = depth[v];
        double room = std::max(m.length_mm + m.tol_mm + d.back_start, m.tol_mm + d.in_start);
        cap[v].along_out = std::min(cap[v].along_out, grow(cap[v + 1].along_in, acc(v), room));
        cap[v].along_in = std::min(cap[v].along_in, cap[v].along_out + skew(v));
    }
    for (std::size_t v = 1; v < n; ++v) {
        if (moves[v].arc || moves[v - 1].arc) continue;
        const Move& m = moves[v - 1];
        const Depths& d = depth[v - 1];
        double room = std::max(m.length_mm + m.tol_mm + d.back_end, m.tol_mm + d.in_end);
        cap[v].along_in = std::min(cap[v].along_in, grow(cap[v - 1].along_out, acc(v - 1), room));
        cap[v].along_out = std::min(cap[v].along_out, cap[v].along_in + skew(v));
    }
}

struct Program {
    std::vector<Move> moves;
    std::vector<Vertex> vertex;
};

Program build(const BenchProgram& prog) {
    Program p;
    AxisArray pos = prog.start_mm;
    double prev_corner_tol = -1;
    for (const PathSegment& seg : prog.segments) {
        for (int k = kDim; k < kAxes; ++k)
            if (std::fabs(seg.end_mm[k] - pos[k]) > 1e-12)
                throw std::runtime_error("line " + std::to_string(seg.line) +
                                         ": the acceleration bound handles X, Y, Z only");
        Move m;
        m.e = seg.kind == SegmentKind::Arc ? make_arc(pos, seg) : make_line(pos, seg.end_mm);
        if (m.e.length_mm < 1e-9) {
            // A move of no length keeps the tool within P of its point, which lies on both
            // neighbours: merging its time into the move before changes nothing.
            if (!p.moves.empty()) {
                p.moves.back().stop_after |= seg.exact_stop;
                p.moves.back().corner_tol_mm =
                    std::min(p.moves.back().corner_tol_mm, seg.tolerance_mm);
            }
            continue;
        }
        m.length_mm = m.e.length_mm;
        m.feed_mm_s = seg.rapid ? 0 : seg.feed_mm_s;
        m.corner_tol_mm = seg.tolerance_mm;
        m.tol_mm = std::max(seg.tolerance_mm, std::max(prev_corner_tol, 0.0));
        m.stop_after = seg.exact_stop;
        m.arc = seg.kind == SegmentKind::Arc;
        m.start = xyz(pos);
        m.end = xyz(seg.end_mm);
        m.u_start = unit_or_zero(xyz(start_derivs(m.e, false).tangent));
        m.u_end = unit_or_zero(xyz(end_derivs(m.e, false).tangent));
        if (m.arc) {
            m.helix = norm(xyz(m.e.c)) > 1e-12;
            Vec3 centre_start = xyz(m.e.origin);  // the centre at the start's off-plane values
            Vec3 centre_end = add(centre_start, xyz(m.e.c));
            m.radial_start = unit_or_zero(sub(m.start, centre_start));
            m.radial_end = unit_or_zero(sub(m.end, centre_end));
            Vec3 normal = cross(xyz(m.e.a), xyz(m.e.b));
            auto in_plane = [&](const Vec3& t) {
                return unit_or_zero(sub(t, scale(normal, dot(t, normal))));
            };
            m.u_start_plane = in_plane(m.u_start);
            m.u_end_plane = in_plane(m.u_end);
        }
        p.moves.push_back(m);
        prev_corner_tol = seg.tolerance_mm;
        pos = seg.end_mm;
    }
    std::size_t n = p.moves.size();
    p.vertex.resize(n + 1);
    p.vertex[0].c = xyz(prog.start_mm);
    for (std::size_t v = 0; v <= n; ++v) {
        if (v > 0) p.vertex[v].c = p.moves[v - 1].end;
        if (v > 0 && v < n) {
            Vertex& vx = p.vertex[v];
            const Move& in = p.moves[v - 1];
            const Move& out = p.moves[v];
            double rho = corner_radius(in, out, vx.c);
            double tol = std::max(in.tol_mm, out.tol_mm);
            vx.ends = false;
            vx.parts = CornerParts{&in, &out, vx.c, spans_within(in, true, 0, rho + tol),
                                   spans_within(out, false, 0, rho + tol)};
        }
    }
    return p;
}

}  // namespace

double corner_region_support_mm(const BenchProgram& prog, std::size_t vertex,
                                const std::array<double, 3>& dir) {
    Program p = build(prog);
    if (vertex >= p.vertex.size()) throw std::out_of_range("corner_region_support_mm: vertex");
    return p.vertex[vertex].h(dir);
}

AccelBoundResult accel_lower_bound(const BenchProgram& prog, const AxisLimits& lim) {
    AccelBoundResult res;
    Program p = build(prog);
    const std::vector<Move>& moves = p.moves;
    std::size_t n = moves.size();
    if (n == 0) return res;

    std::vector<Depths> depth(n);
    for (std::size_t i = 0; i < n; ++i)
        depth[i] = depths_of(moves[i], p.vertex[i], p.vertex[i + 1]);
    std::vector<Vec3> spread(n + 1);
    for (std::size_t v = 0; v <= n; ++v) spread[v] = p.vertex[v].spread();
    Context cx{moves, p.vertex, depth, spread, lim};
    std::vector<CornerCaps> cap(n + 1);
    for (std::size_t v = 0; v <= n; ++v) cap[v] = corner_caps(cx, v, res.capped_corners, res.stops);
    propagate_caps(moves, depth, lim, cap);

    // Step 2, lines chained through their vertices. Line i runs from vertex i to i + 1 along u;
    // o_v = q(t_v) - c_v and z_v = u_in(v) . o_v, u_in(v) the direction of the line ending at v.
    // During [t_i, t_i+1], y = u . q moves by L + u . o_{i+1} - u . o_i, where u . o_{i+1} =
    // z_{i+1} and u . o_i = z_i + (u - u_in(i)) . o_i <= z_i + h_i(u - u_in(i)). z_v lies in
    // [-h_v(-u_in), h_v(u_in)]. Minimise the sum of piece times over the z on a grid of cells
    // (taking each cell's worst end), a dynamic programme along the chain. The program's ends pin
    // o = 0; an arc cuts the chain (the line after it starts from h_v(u), the line before it ends
    // at -h_v(-u), whatever the arc's own piece assumed).
    struct Chain {
        std::array<double, kCells> best{};  // least time so far with z of the last vertex in cell
        double lo = 0, hi = 0;              // z range of the last vertex, split into kCells
        bool pinned = true;                 // z = 0 exactly (program start)
        bool open = false;                  // the last piece was a line (z and u_in are defined)
        Vec3 u_in{};
    };
    auto cell_edge = [](const Chain& ch, int cell) {
        return ch.lo + (ch.hi - ch.lo) * cell / kCells;
    };
    Chain st;
    double total = 0;
    auto close_chain = [&](const Chain& ch) {
        return ch.pinned ? ch.best[0] : *std::min_element(ch.best.begin(), ch.best.end());
    };
    for (std::size_t i = 0; i < n; ++i) {
        const Move& m = moves[i];
        if (m.arc) {
            total += close_chain(st);
            total += arc_time(m, depth[i], cap[i].speed, cap[i + 1].speed, lim, res.arc_windows);
            st = Chain{};
            st.pinned = false;
            st.open = false;
            st.best.fill(0);
            continue;
        }
        Vec3 u = m.u_start;
        double vmax = feed_cap(m, u, lim), acc = box_support(u, lim.acc_mm_s2);
        bool last = i + 1 == n;
        Chain next;
        next.pinned = last;
        next.open = true;
        next.u_in = u;
        next.lo = last ? 0 : -depth[i].in_end;
        next.hi = last ? 0 : depth[i].back_end;
        // Start term, as a function of the previous cell's upper edge.
        double skew = 0;  // h_i(u - u_in(i)) when chained
        double fixed_start = 0;
        if (!st.pinned && !st.open) fixed_start = depth[i].in_start;  // after an arc
        if (!st.pinned && st.open) skew = p.vertex[i].h(sub(u, st.u_in));
        int in_cells = (st.pinned || !st.open) ? 1 : kCells, out_cells = last ? 1 : kCells;
        for (int a = 0; a < out_cells; ++a) {
            double z_end_lo = last ? 0 : cell_edge(next, a);
            double best = kInf;
            for (int b = 0; b < in_cells; ++b) {
                double start_hi =
                    st.pinned ? 0 : (st.open ? cell_edge(st, b + 1) + skew : fixed_start);
                double prev = st.best[b];  // 0 after an arc (its time is in total already)
                double d = m.length_mm + z_end_lo - start_hi;
                best = std::min(
                    best, prev + min_time_1d(d, cap[i].along_out, cap[i + 1].along_in, vmax, acc));
            }
            next.best[a] = best;
        }
        st = next;
    }
    total += close_chain(st);
    res.time_s = total + prog.dwell_s;
    return res;
}

}  // namespace motion::bench
