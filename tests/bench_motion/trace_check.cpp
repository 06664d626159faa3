// Trace check (trace_check.hpp): distance of each sample from the programmed path, finite
// differences for the axis velocities and accelerations.
#include "trace_check.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "motion/geometry.hpp"

namespace motion::bench {
namespace {

using P3 = std::array<double, 3>;
constexpr double kTwoPi = 6.28318530717958647692;
// Moves searched around the last nearest one: a few behind (blends can reach back past a short
// move) and ahead as far as the path goes within kSearchAhead_mm of the nearest move's end (a
// period moves the tool well under 1 mm). Searching the whole path instead would match a
// program that retraces its path (a rapid back along a cut) to the wrong pass.
constexpr std::size_t kSearchBack = 8;
constexpr double kSearchAhead_mm = 5;
// A sample beyond the tolerance of the moves searched is checked against the whole path (the
// smaller distance counts: it can only understate a deviation), and the search goes on there.

struct Move {
    Element e;
    bool arc = false;
    double feed_mm_s = 0;  // 0 = rapid
    double tolerance_mm = 0;
    std::int32_t line = 0;
};

double dist(const P3& a, const AxisArray& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
}

double dist_at(const Move& m, const P3& q, double s) {
    CurvePoint cp;
    evaluate(m.e, std::clamp(s, 0.0, m.e.length_mm), cp);
    return dist(q, cp.p);
}

double line_distance(const Move& m, const P3& q) {
    double t = 0;
    for (int k = 0; k < 3; ++k) t += (q[k] - m.e.origin[k]) * m.e.a[k];
    return dist_at(m, q, t);
}

// The arc point at the sample's angle about the centre (each turn of a helix), refined by a
// golden-section search along s (exact for plane arcs; a helix's nearest point is near it).
double arc_distance(const Move& m, const P3& q) {
    const Element& e = m.e;
    double pu = 0, pw = 0;
    for (int k = 0; k < 3; ++k) {
        pu += (q[k] - e.origin[k]) * e.a[k];
        pw += (q[k] - e.origin[k]) * e.b[k];
    }
    double sweep = std::fabs(e.sweep_rad), sgn = e.sweep_rad >= 0 ? 1 : -1;
    double at = std::fmod(sgn * (std::atan2(pw, pu) - e.theta0_rad), kTwoPi);
    if (at < 0) at += kTwoPi;
    double best = std::min(dist_at(m, q, 0), dist_at(m, q, e.length_mm));
    double span = e.length_mm * std::min(1.0, 0.2 / std::max(sweep, 1e-9));
    for (double a = at; a <= sweep; a += kTwoPi) {
        double s0 = e.length_mm * a / sweep;
        double lo = s0 - span, hi = s0 + span;
        for (int i = 0; i < 40; ++i) {
            double m1 = hi - (hi - lo) * 0.6180339887, m2 = lo + (hi - lo) * 0.6180339887;
            if (dist_at(m, q, m1) < dist_at(m, q, m2))
                hi = m2;
            else
                lo = m1;
        }
        best = std::min({best, dist_at(m, q, s0), dist_at(m, q, (lo + hi) / 2)});
    }
    return best;
}

double move_distance(const Move& m, const P3& q) {
    return m.arc ? arc_distance(m, q) : line_distance(m, q);
}

}  // namespace

std::vector<P3> read_trace(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open the trace");
    std::vector<P3> out;
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        std::istringstream fields(text);
        P3 p{};
        if (!(fields >> p[0] >> p[1] >> p[2]))
            throw std::runtime_error(path + ":" + std::to_string(line) +
                                     ": expected three numbers X Y Z");
        out.push_back(p);
    }
    if (out.empty()) throw std::runtime_error(path + ": the trace is empty");
    return out;
}

TraceReport check_trace(const BenchProgram& prog, const std::vector<P3>& trace, double period_s,
                        double quantum_mm) {
    std::vector<Move> moves;
    AxisArray pos = prog.start_mm;
    for (const PathSegment& seg : prog.segments) {
        Move m;
        m.e = seg.kind == SegmentKind::Arc ? make_arc(pos, seg) : make_line(pos, seg.end_mm);
        pos = seg.end_mm;
        if (m.e.length_mm < 1e-9) continue;
        m.arc = seg.kind == SegmentKind::Arc;
        m.feed_mm_s = seg.rapid ? 0 : seg.feed_mm_s;
        m.tolerance_mm = seg.tolerance_mm;
        m.line = seg.line;
        moves.push_back(m);
    }
    if (moves.empty()) throw std::runtime_error("the program has no moves");
    TraceReport rep;
    rep.samples = long(trace.size());
    std::size_t near = 0;
    for (std::size_t n = 0; n < trace.size(); ++n) {
        const P3& q = trace[n];
        std::size_t lo = near > kSearchBack ? near - kSearchBack : 0;
        std::size_t hi = near + 1;
        for (double ahead = 0; hi < moves.size() && ahead <= kSearchAhead_mm; ++hi)
            ahead += moves[hi].e.length_mm;
        double best = INFINITY;
        for (std::size_t i = lo; i < hi; ++i) {
            double d = move_distance(moves[i], q);
            if (d < best) best = d, near = i;
        }
        double local_tol = std::max(moves[near].tolerance_mm,
                                    near > 0 ? moves[near - 1].tolerance_mm : 0.0);
        if (best > local_tol + quantum_mm) {
            // Forward first (ties go to the later pass of a retraced path), then behind.
            for (std::size_t i = hi; i < moves.size(); ++i) {
                double d = move_distance(moves[i], q);
                if (d < best) best = d, near = i;
            }
            for (std::size_t i = 0; i < lo; ++i) {
                double d = move_distance(moves[i], q);
                if (d < best) best = d, near = i;
            }
        }
        // A corner belongs to both moves: the larger tolerance applies there.
        double tol = moves[near].tolerance_mm;
        if (near > 0) tol = std::max(tol, moves[near - 1].tolerance_mm);
        bool rapid = moves[near].feed_mm_s == 0;
        (rapid ? rep.max_deviation_rapid_mm : rep.max_deviation_feed_mm) =
            std::max(rapid ? rep.max_deviation_rapid_mm : rep.max_deviation_feed_mm, best);
        if (best > tol + quantum_mm) {
            ++rep.samples_over_tolerance;
            ++(rapid ? rep.over_tolerance_rapid : rep.over_tolerance_feed);
            double& worst = rep.over_by_line[moves[near].line];
            worst = std::max(worst, best);
        }
        if (best > rep.max_deviation_mm) {
            rep.max_deviation_mm = best;
            rep.deviation_line = moves[near].line;
            rep.deviation_sample = long(n);
            rep.deviation_tolerance_mm = tol;
        }
        if (n >= 1) {
            double speed2 = 0;
            for (int k = 0; k < 3; ++k) {
                double v = (q[k] - trace[n - 1][k]) / period_s;
                speed2 += v * v;
                rep.max_vel_mm_s[k] = std::max(rep.max_vel_mm_s[k], std::fabs(v));
            }
            if (moves[near].feed_mm_s > 0)
                rep.max_speed_over_feed = std::max(rep.max_speed_over_feed,
                                                   std::sqrt(speed2) / moves[near].feed_mm_s);
        }
        if (n >= 2)
            for (int k = 0; k < 3; ++k) {
                double a = (q[k] - 2 * trace[n - 1][k] + trace[n - 2][k]) / (period_s * period_s);
                rep.max_acc_mm_s2[k] = std::max(rep.max_acc_mm_s2[k], std::fabs(a));
            }
    }
    rep.end_error_mm = dist(trace.back(), prog.segments.back().end_mm);
    return rep;
}

}  // namespace motion::bench
