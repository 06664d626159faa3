#include "motion/jerk_stop.hpp"

#include <algorithm>
#include <cmath>

namespace motion {
namespace {

struct Pieces {
    double j1 = 0, t1 = 0;  // piece 1: jerk and duration
    double t2 = 0;          // piece 2 at -decel
    double t3 = 0;          // piece 3 at +jerk
};

// Piece 1 takes a from a0 to -d (jerk -j when it must brake harder, +j when it brakes too hard
// already). Piece 3 loses d^2 / 2j of speed, so piece 2 runs from the speed piece 1 ends at to
// that one, at -d.
Pieces pieces(const JerkStopState& s, double d, double j) {
    Pieces p;
    p.j1 = s.a_mm_s2 > -d ? -j : j;
    p.t1 = std::fabs(s.a_mm_s2 + d) / j;
    const double v1 = s.v_mm_s + s.a_mm_s2 * p.t1 + p.j1 * p.t1 * p.t1 / 2;
    const double v2 = d * d / (2 * j);
    p.t2 = d > 0 ? std::max(0.0, (v1 - v2) / d) : 0.0;
    p.t3 = d / j;
    return p;
}

// Exact cubic motion for h at constant jerk.
void advance(double& v, double& a, double& s, double jerk, double h) {
    s += v * h + a * h * h / 2 + jerk * h * h * h / 6;
    v += a * h + jerk * h * h / 2;
    a += jerk * h;
}

}  // namespace

// Braking harder than now (d > -a0), piece 1 ends at v0 + (a0^2 - d^2) / 2j, and piece 2 is
// empty when that equals d^2 / 2j. Braking less (d < -a0), piece 2 is never empty unless the
// stop is already too late (v0 < a0^2 / 2j: speed runs out before the deceleration does).
double jerk_stop_max_peak(const JerkStopState& s, double j) noexcept {
    return std::sqrt(std::max(0.0, (2 * j * s.v_mm_s + s.a_mm_s2 * s.a_mm_s2) / 2));
}

double jerk_stop_distance(const JerkStopState& s, double decel, double j) noexcept {
    const double d = std::min(decel, jerk_stop_max_peak(s, j));
    const Pieces p = pieces(s, d, j);
    double v = s.v_mm_s, a = s.a_mm_s2, dist = 0;
    advance(v, a, dist, p.j1, p.t1);
    advance(v, a, dist, 0, p.t2);
    advance(v, a, dist, j, p.t3);
    return dist;
}

std::optional<double> jerk_stop_decel_for(const JerkStopState& s, double distance_mm,
                                          double max_decel, double j) noexcept {
    const double too_late_v = s.a_mm_s2 < 0 ? s.a_mm_s2 * s.a_mm_s2 / (2 * j) : 0.0;
    if (s.v_mm_s < too_late_v * (1 - 1e-6) - 1e-9) return std::nullopt;  // no jerk-limited stop
    double hi = std::min(max_decel, jerk_stop_max_peak(s, j));
    if (!(hi > 0)) return std::nullopt;
    // On the last piece the state sits on the shortest stop itself, give or take rounding: a
    // nanometre too long is the same stop (the caller lands on the point).
    constexpr double kSlack_mm = 1e-6;
    const double shortest_mm = jerk_stop_distance(s, hi, j);
    if (shortest_mm > distance_mm + kSlack_mm) return std::nullopt;
    if (shortest_mm >= distance_mm) return hi;
    double lo = hi * 1e-9;
    if (jerk_stop_distance(s, lo, j) <= distance_mm) return lo;
    for (int i = 0; i < 60; ++i) {  // S(d) falls as d grows
        const double mid = (lo + hi) / 2;
        if (jerk_stop_distance(s, mid, j) > distance_mm)
            lo = mid;
        else
            hi = mid;
    }
    return hi;
}

JerkStopStep jerk_stop_step(const JerkStopState& s, double decel, double j, double dt) noexcept {
    const double d = std::min(decel, jerk_stop_max_peak(s, j));
    const Pieces p = pieces(s, d, j);
    JerkStopStep out;
    double v = s.v_mm_s, a = s.a_mm_s2, dist = 0, left = dt;
    const double jerks[3] = {p.j1, 0.0, j}, times[3] = {p.t1, p.t2, p.t3};
    for (int i = 0; i < 3 && left > 0; ++i) {
        const double h = std::min(left, times[i]);
        advance(v, a, dist, jerks[i], h);
        left -= h;
        out.jerk_mm_s3 = jerks[i];
    }
    out.at_rest = left > 0 || v <= 0;
    if (out.at_rest) {
        v = 0;
        a = 0;
        out.jerk_mm_s3 = 0;
    }
    out.next = {std::max(v, 0.0), a};
    out.ds_mm = dist;
    return out;
}

}  // namespace motion
