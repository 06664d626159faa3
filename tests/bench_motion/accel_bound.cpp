// The acceleration-aware lower bound (accel_bound.hpp). The proof sketch is in
// docs/benchmarks.md; each function below names the step it implements.
//
// Model: the tool position q(t) follows the path p(s) with a continuous, non-decreasing
// parameter s(t) and |q(t) - p(s(t))| <= P; |dq_k/dt| <= V_k, |d2q_k/dt2| <= A_k; |dq/dt| <= F on
// feed moves; at rest at the program's start and end points. The motion is split at the instants
// s(t) passes each programmed end point (vertex); the pieces are disjoint in time, so a lower
// bound on each piece adds up to a lower bound on the whole.
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
// Offset grid for the chained line pieces (see ChainState): cells of 2P / kCells.
constexpr int kCells = 24;
// Arc points per full turn when an arc's extent along a direction is taken from samples.
constexpr int kArcSamplesPerTurn = 128;
// Window half-angles tried at an arc's extreme point.
constexpr int kWindowSteps = 48;
// Rounds of shrinking the reach with the component bound found so far (component_bound).
constexpr int kReachRounds = 4;

struct Move {
    Element e;
    double length_mm = 0;
    double feed_mm_s = 0;  // 0 = rapid
    double tolerance_mm = 0;
    bool stop_after = false;  // G09 or a dwell: at rest at its end
    bool arc = false;
};

double dot(const Vec3& a, const Vec3& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double norm(const Vec3& a) {
    return std::sqrt(dot(a, a));
}
Vec3 sub(const Vec3& a, const Vec3& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
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

Vec3 point_at(const Move& m, double s_mm) {
    CurvePoint cp;
    evaluate(m.e, s_mm, cp);
    return xyz(cp.p);
}

// Points of a move whose hull, grown by the returned margin, contains the move: the end points
// for a line; samples plus the sagitta between them for an arc.
double hull_points(const Move& m, std::vector<Vec3>& pts) {
    pts.clear();
    if (!m.arc) {
        pts.push_back(xyz(m.e.origin));
        pts.push_back(xyz(m.e.end));
        return 0;
    }
    int n = std::max(4, int(std::ceil(std::fabs(m.e.sweep_rad) / (2 * kPi) * kArcSamplesPerTurn)));
    for (int i = 0; i <= n; ++i) pts.push_back(point_at(m, m.length_mm * i / n));
    double half_step = std::fabs(m.e.sweep_rad) / n / 2;
    return m.e.radius_mm * (1 - std::cos(half_step));
}

// What the tool can reach while a velocity component is braked: a box about the vertex (axis k
// moves at most V_k times the braking time, plus 2P) and the braking time itself, which also
// limits how far along the path s can get (see extent()).
struct Reach {
    Vec3 box_mm;
    double time_s;
    double tol_mm;      // the program's largest P
    double vtool_mm_s;  // the tool's largest speed, |q'| <= sqrt(sum_k V_k^2)
};

// Largest d . (p - c) over the path from vertex v onwards (forward) or backwards, as far as the
// tool can get while its velocity component along d is braked: s cannot pass the first point of
// the path outside the box (the tool is within P of c and of the path), nor get further than the
// braking time allows: between the instants s passes two points of the path the tool moves at
// least their distance less 2P, at most at the feed (feed moves) or at its largest speed. A line
// counts up to where it leaves; an arc up to its first sample out of reach (its hull from the
// start to there, grown by the sagitta, holds the part within). Past the program's ends the tool
// rests at the end point, which counts too.
double extent(const std::vector<Move>& moves, const std::vector<Vec3>& vertex, std::size_t v,
              const Vec3& d, bool forward, const Reach& reach) {
    const Vec3& c = vertex[v];
    auto inside = [&](const Vec3& r) {
        for (int k = 0; k < kDim; ++k)
            if (std::fabs(r[k]) > reach.box_mm[k]) return false;
        return true;
    };
    double best = 0;  // c itself
    double time_left_s = reach.time_s;
    std::vector<Vec3> pts;
    std::size_t n = moves.size();
    for (std::size_t step = 0;; ++step) {
        std::size_t i;  // move index
        if (forward) {
            if (v + step >= n) break;
            i = v + step;
        } else {
            if (step >= v) break;
            i = v - 1 - step;
        }
        const Move& m = moves[i];
        double speed = m.feed_mm_s > 0 ? std::min(m.feed_mm_s, reach.vtool_mm_s) : reach.vtool_mm_s;
        // Time to get from one point of the path to another d_mm away, at least.
        auto least_time = [&](double d_mm) {
            return std::max(0.0, d_mm - 2 * reach.tol_mm) / speed;
        };
        if (!m.arc) {
            Vec3 a = sub(xyz(forward ? m.e.origin : m.e.end), c);
            Vec3 b = sub(xyz(forward ? m.e.end : m.e.origin), c);
            // Where the line leaves the box (a is inside) or the time runs out.
            double t_exit = std::min(1.0, (speed * time_left_s + 2 * reach.tol_mm) / m.length_mm);
            for (int k = 0; k < kDim; ++k) {
                double span = b[k] - a[k];
                double lim = reach.box_mm[k];
                if (b[k] > lim) t_exit = std::min(t_exit, (lim - a[k]) / span);
                if (b[k] < -lim) t_exit = std::min(t_exit, (-lim - a[k]) / span);
            }
            t_exit = std::max(t_exit, 0.0);
            Vec3 e{a[0] + t_exit * (b[0] - a[0]), a[1] + t_exit * (b[1] - a[1]),
                   a[2] + t_exit * (b[2] - a[2])};
            best = std::max({best, dot(d, a), dot(d, e)});
            if (t_exit < 1) break;
            time_left_s -= least_time(m.length_mm);
            continue;
        }
        double margin = hull_points(m, pts);
        if (!forward) std::reverse(pts.begin(), pts.end());
        bool left = false;
        for (std::size_t j = 0; j < pts.size(); ++j) {
            Vec3 r = sub(pts[j], c);
            best = std::max(best, dot(d, r) + margin);
            if (j > 0) time_left_s -= least_time(norm(sub(pts[j], pts[j - 1])));
            if ((left = !inside(r) || time_left_s < 0)) break;
        }
        if (left) break;
    }
    return best;
}

struct CornerContext {
    const std::vector<Move>& moves;
    const std::vector<Vec3>& vertex;
    const AxisLimits& lim;
    Reach reach;        // with the longest braking time, see extent()
    double tol_max_mm;  // later path points count within the program's largest P
};

// Upper bound on |d . q'| at the instant s passes vertex v, for one direction d (either sign):
// forward in time the tool cannot overshoot the path's extent along d by more than P after being
// within P of the vertex, so (d . q')^2 <= 2 A_d (E_fwd + 2P), and backward in time likewise
// (the second P is the program's largest, for the later path points). Braking w takes w / A_d,
// so a bound on w shrinks the reach (axis k moves at most V_k w / A_d meanwhile), which can
// lower the bound again: a few rounds, each sound given the last.
double component_bound(const CornerContext& cx, std::size_t v, const Vec3& d, double tol_mm) {
    double a_d = box_support(d, cx.lim.acc_mm_s2);
    auto one_sign = [&](const Vec3& dir) {
        Vec3 back{-dir[0], -dir[1], -dir[2]};
        double w = box_support(dir, cx.lim.vel_mm_s);
        Reach reach = cx.reach;
        for (int round = 0; round < kReachRounds; ++round) {
            double e = std::min(extent(cx.moves, cx.vertex, v, dir, true, reach),
                                extent(cx.moves, cx.vertex, v, back, false, reach));
            double w_next = std::sqrt(2 * a_d * (e + tol_mm + cx.tol_max_mm));
            if (w_next >= w) break;
            w = w_next;
            reach.time_s = std::min(reach.time_s, w / a_d);
            for (int k = 0; k < kDim; ++k)
                reach.box_mm[k] =
                    std::min(reach.box_mm[k], 2 * cx.tol_max_mm + cx.lim.vel_mm_s[k] * w / a_d);
        }
        return w;
    };
    return std::max(one_sign(d), one_sign({-d[0], -d[1], -d[2]}));
}

Vec3 end_tangent(const Move& m) {
    return unit_or_zero(xyz(end_derivs(m.e).tangent));
}
Vec3 start_tangent(const Move& m) {
    return unit_or_zero(xyz(start_derivs(m.e).tangent));
}

// Speed bounds at vertex v (between moves v-1 and v; 0 and n are the program's ends): on |q'|
// (for arcs, which are timed along the tool's path) and on the components of q' along the
// incoming and the outgoing tangent (for lines, which are timed along their direction). Corners
// that turn by less than 90 degrees get none: the argument cannot bound the component along
// the way the path goes on.
struct CornerCaps {
    double speed = kInf, along_in = kInf, along_out = kInf;
};

CornerCaps corner_caps(const CornerContext& cx, std::size_t v, int& capped, int& stops) {
    std::size_t n = cx.moves.size();
    CornerCaps stop{0, 0, 0};
    if (v == 0 || v == n) return ++stops, stop;
    const Move& in = cx.moves[v - 1];
    if (in.stop_after) return ++stops, stop;
    Vec3 u1 = end_tangent(in), u2 = start_tangent(cx.moves[v]);
    double cos_turn = dot(u1, u2);
    if (cos_turn > 1 - 1e-12) return {};            // tangent
    if (in.tolerance_mm <= 0) return ++stops, stop;  // G61: a kink on the exact path is a stop
    Vec3 e2 = unit_or_zero(sub(u2, {cos_turn * u1[0], cos_turn * u1[1], cos_turn * u1[2]}));
    if (norm(e2) == 0)
        e2 = unit_or_zero(cross(u1, std::fabs(u1[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    Vec3 e3 = cross(u1, e2);
    CornerCaps caps;
    double sum2 = 0;
    for (const Vec3& d : {u1, e2, e3}) {
        double b = component_bound(cx, v, d, in.tolerance_mm);
        sum2 += b * b;
    }
    // The axes' own components bound those along u1 and u2 too (|u . q'| <= sum_k |u_k| |q'_k|),
    // which is tighter where a line is nearly along an axis whose path stops there (the end of a
    // sine row: u1 is 5 degrees off X, and the path goes on along u1 only by that skew).
    Vec3 axis_caps, speed_axes{0, 0, 0};
    for (int k = 0; k < kDim; ++k) {
        Vec3 ek{0, 0, 0};
        ek[k] = 1;
        axis_caps[k] = component_bound(cx, v, ek, in.tolerance_mm);
        speed_axes[k] = axis_caps[k] * axis_caps[k];
    }
    caps.speed =
        std::min(std::sqrt(sum2), std::sqrt(speed_axes[0] + speed_axes[1] + speed_axes[2]));
    auto via_axes = [&](const Vec3& u) {
        return std::fabs(u[0]) * axis_caps[0] + std::fabs(u[1]) * axis_caps[1] +
               std::fabs(u[2]) * axis_caps[2];
    };
    caps.along_in = std::min(component_bound(cx, v, u1, in.tolerance_mm), via_axes(u1));
    caps.along_out = std::min(component_bound(cx, v, u2, in.tolerance_mm), via_axes(u2));
    ++capped;
    return caps;
}

double feed_cap(const Move& m, const Vec3& dir, const AxisLimits& lim) {
    double v = box_support(dir, lim.vel_mm_s);
    return m.feed_mm_s > 0 ? std::min(m.feed_mm_s, v) : v;
}

// Time bound for an arc piece: the larger of (a) its in-plane length, shortened by the tolerance,
// at the feed from its corner speed bounds and (b) the turning time at each extreme point of a
// plane axis (where that axis reverses) plus the rest of the arc at the feed.
double arc_time(const Move& m, double cap_in, double cap_out, const AxisLimits& lim,
                int& windows) {
    double r = m.e.radius_mm, tol = m.tolerance_mm;
    double sweep = std::fabs(m.e.sweep_rad);
    if (r <= 2 * tol) return 0;
    double inner = r - tol;
    // The tool stays at least r - P from the centre and starts and ends within P of the arc's
    // ends: it sweeps at least |sweep| - 2 beta about the centre, beta = asin(P / (r - P)).
    double beta = std::asin(std::min(1.0, tol / inner));
    Vec3 u = xyz(m.e.a), w = xyz(m.e.b);
    double plane_vmax = 0, plane_acc = 0;
    for (int k = 0; k < kDim; ++k) {
        double in_plane = std::hypot(u[k], w[k]);
        plane_vmax += lim.vel_mm_s[k] * in_plane * lim.vel_mm_s[k] * in_plane;
        plane_acc += lim.acc_mm_s2[k] * in_plane * lim.acc_mm_s2[k] * in_plane;
    }
    double feed = m.feed_mm_s > 0 ? std::min(m.feed_mm_s, std::sqrt(plane_vmax))
                                  : std::sqrt(plane_vmax);
    double full = min_time_1d(inner * (sweep - 2 * beta), cap_in, cap_out, feed,
                              std::sqrt(plane_acc));

    // Extreme points: axis k's coordinate is r m_k cos(theta - phi_k) about the centre.
    double th0 = m.e.theta0_rad, sgn = m.e.sweep_rad >= 0 ? 1 : -1;
    double extra_s = 0;
    int pieces = 1;
    for (int k = 0; k < kDim; ++k) {
        double mk = std::hypot(u[k], w[k]);
        if (mk < 1e-9) continue;
        double phi = std::atan2(w[k], u[k]);
        // Angles phi + j pi inside the sweep, measured from the start along the sweep.
        double first = std::fmod(sgn * (phi - th0), kPi);
        if (first < 0) first += kPi;
        for (double at = first; at < sweep; at += kPi) {
            double half_max = std::min({kPi / 4, at, sweep - at});
            double best_gain = 0;
            for (int i = 1; i <= kWindowSteps; ++i) {
                double half = half_max * i / kWindowSteps;
                double h = r * mk * (1 - std::cos(half)) - 2 * tol;
                double turn = 2 * turn_time_1d(h, lim.vel_mm_s[k], lim.acc_mm_s2[k]);
                double at_feed = inner * std::max(0.0, 2 * half - 2 * beta) / feed;
                double gain = std::max(turn, at_feed) - inner * 2 * half / feed;
                best_gain = std::max(best_gain, gain);
            }
            if (best_gain <= 0) continue;
            extra_s += best_gain;
            pieces += 2;
            ++windows;
        }
    }
    // Every piece boundary costs up to 2 beta of sweep (within P of its end points).
    double rest = inner * std::max(0.0, sweep - pieces * 2 * beta) / feed;
    double with_windows = rest + extra_s;
    if (extra_s == 0) return full;
    return std::max(full, with_windows);
}

// Lines chained through their vertices: piece i runs from vertex i-1 to vertex i and its
// direction u_i. With o_v the tool's offset from vertex v when s passes it (|o_v| <= P) and
// z_v = u_v . o_v, the tool covers along u_i at least L_i + z_i - z_{i-1} - P |u_i - u_{i-1}|.
// The z are unknown: minimise the sum of piece times over them on a grid of cells (taking each
// cell's worst end), a dynamic programme along the chain. Arcs cut the chain (their offsets are
// taken as free). Returns the bound for moves [0, n).
struct ChainState {
    std::array<double, kCells> best{};  // least time so far with z of the last vertex in cell m
    bool pinned = true;                 // z = 0 exactly (program start)
};

// Carries the component caps of step 1 along chains of lines (a backward and a forward pass),
// so that a run of short moves into a corner must slow down before its last move. During line
// i (from vertex i to i + 1, direction u) the tool stays within P of it, so y = u . q moves at
// most L + 2P forwards, with |y''| <= A_u = sum_k A_k |u_k|: to end the line with y' within the
// cap B at vertex i + 1 it must start with y' <= sqrt(B^2 + 2 A_u (L + 2P)), and the same
// forwards. At a vertex the components along the two lines' directions belong to one velocity,
// so they differ by at most (u_i - u_{i+1}) . q' <= sum_k V_k |u_i,k - u_{i+1},k|. Arcs cut the
// chain (their caps stay as step 1 gives them).
void propagate_caps(const std::vector<Move>& moves, const AxisLimits& lim, double tol_mm,
                    std::vector<CornerCaps>& cap) {
    std::size_t n = moves.size();
    auto line_dir = [&](std::size_t i) { return start_tangent(moves[i]); };
    auto reach_speed = [&](std::size_t i, double from) {
        double acc = box_support(line_dir(i), lim.acc_mm_s2);
        return std::sqrt(from * from + 2 * acc * (moves[i].length_mm + 2 * tol_mm));
    };
    auto skew = [&](std::size_t v) {  // vertex v joins lines v - 1 and v
        return box_support(sub(line_dir(v - 1), line_dir(v)), lim.vel_mm_s);
    };
    for (std::size_t v = n - 1; v >= 1; --v) {
        if (moves[v].arc || moves[v - 1].arc) continue;
        cap[v].along_out = std::min(cap[v].along_out, reach_speed(v, cap[v + 1].along_in));
        cap[v].along_in = std::min(cap[v].along_in, cap[v].along_out + skew(v));
    }
    for (std::size_t v = 1; v < n; ++v) {
        if (moves[v].arc || moves[v - 1].arc) continue;
        cap[v].along_in = std::min(cap[v].along_in, reach_speed(v - 1, cap[v - 1].along_out));
        cap[v].along_out = std::min(cap[v].along_out, cap[v].along_in + skew(v));
    }
}

}  // namespace

AccelBoundResult accel_lower_bound(const BenchProgram& prog, const AxisLimits& lim) {
    AccelBoundResult res;
    std::vector<Move> moves;
    std::vector<Vec3> vertex{xyz(prog.start_mm)};
    AxisArray pos = prog.start_mm;
    for (const PathSegment& seg : prog.segments) {
        for (int k = kDim; k < kAxes; ++k)
            if (std::fabs(seg.end_mm[k] - pos[k]) > 1e-12)
                throw std::runtime_error("line " + std::to_string(seg.line) +
                                         ": the acceleration bound handles X, Y, Z only");
        Move m;
        m.e = seg.kind == SegmentKind::Arc ? make_arc(pos, seg) : make_line(pos, seg.end_mm);
        if (m.e.length_mm < 1e-9) {
            if (!moves.empty()) moves.back().stop_after |= seg.exact_stop;
            continue;
        }
        m.length_mm = m.e.length_mm;
        m.feed_mm_s = seg.rapid ? 0 : seg.feed_mm_s;
        m.tolerance_mm = seg.tolerance_mm;
        m.stop_after = seg.exact_stop;
        m.arc = seg.kind == SegmentKind::Arc;
        moves.push_back(m);
        vertex.push_back(xyz(seg.end_mm));
        pos = seg.end_mm;
    }
    std::size_t n = moves.size();
    if (n == 0) return res;

    // How far each axis can get while one velocity component is braked: V_k times the longest
    // braking time, plus 2P (max P in the program). The component w = d . q' is at most
    // sum_k V_k |d_k| and is braked at A_d = sum_k A_k |d_k|, so braking takes at most
    // w / A_d <= max_k V_k / A_k.
    double brake_s = 0, tol_max = 0;
    for (int k = 0; k < kDim; ++k) brake_s = std::max(brake_s, lim.vel_mm_s[k] / lim.acc_mm_s2[k]);
    for (const Move& m : moves) tol_max = std::max(tol_max, m.tolerance_mm);
    Reach reach{{}, brake_s, tol_max, 0};
    for (int k = 0; k < kDim; ++k) {
        reach.box_mm[k] = 2 * tol_max + lim.vel_mm_s[k] * brake_s;
        reach.vtool_mm_s += lim.vel_mm_s[k] * lim.vel_mm_s[k];
    }
    reach.vtool_mm_s = std::sqrt(reach.vtool_mm_s);
    CornerContext cx{moves, vertex, lim, reach, tol_max};
    std::vector<CornerCaps> cap(n + 1);
    for (std::size_t v = 0; v <= n; ++v)
        cap[v] = corner_caps(cx, v, res.capped_corners, res.stops);
    propagate_caps(moves, lim, tol_max, cap);

    // Offset grid: cell m covers z in [g(m), g(m+1)], g(m) = P (2m / kCells - 1).
    ChainState st;
    double total = 0;
    Vec3 prev_dir{0, 0, 0};
    double prev_tol = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const Move& m = moves[i];
        if (m.arc) {
            double least = st.pinned ? st.best[0] : *std::min_element(st.best.begin(), st.best.end());
            total += least + arc_time(m, cap[i].speed, cap[i + 1].speed, lim, res.arc_windows);
            st = ChainState{};
            st.pinned = false;
            st.best.fill(0);
            prev_dir = {0, 0, 0};
            prev_tol = m.tolerance_mm;
            continue;
        }
        Vec3 u = start_tangent(m);
        double vmax = feed_cap(m, u, lim), acc = box_support(u, lim.acc_mm_s2);
        // Offsets at the start vertex: pinned (0) at the program start, else the previous
        // move's cells; after an arc, anything within P of the vertex.
        double p_start = prev_tol;
        double skew = norm(prev_dir) > 0 ? p_start * norm(sub(u, prev_dir)) : 0;
        bool last = i + 1 == n;
        double p_end = m.tolerance_mm;
        ChainState next;
        next.pinned = last;
        auto g = [](double p, int cell) { return p * (2.0 * cell / kCells - 1); };
        int in_cells = st.pinned ? 1 : kCells, out_cells = last ? 1 : kCells;
        for (int a = 0; a < out_cells; ++a) {
            double z_end_lo = last ? 0 : g(p_end, a);
            double best = kInf;
            for (int b = 0; b < in_cells; ++b) {
                double z_start_hi = st.pinned ? 0 : g(p_start, b + 1);
                double d = m.length_mm + z_end_lo - z_start_hi - skew;
                best = std::min(best, st.best[b] + min_time_1d(d, cap[i].along_out, cap[i + 1].along_in, vmax, acc));
            }
            next.best[a] = best;
        }
        st = next;
        prev_dir = u;
        prev_tol = m.tolerance_mm;
    }
    total += st.pinned ? st.best[0] : *std::min_element(st.best.begin(), st.best.end());
    res.time_s = total + prog.dwell_s;
    return res;
}

}  // namespace motion::bench
