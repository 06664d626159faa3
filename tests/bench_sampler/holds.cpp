// bench_sampler --holds: how soon a hold (or an override step) takes effect with a jerk limit,
// in the cases docs/benchmarks.md and docs/motion-planner.md quote. 1 ms periods on a simulated
// clock, so the figures do not depend on the machine or its load. Every period of every run is
// checked against the axis limits (the tests' LimitCheck, tests/motion/sampler_support.hpp); a
// run that leaves them, or a hold that never ends, makes the exit status 1.
#include "holds.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "sampler_support.hpp"

namespace sampler_holds {
namespace {

using namespace motion;
using test::feed_to;
using test::uniform;

// A full circle of radius_mm about (radius_mm, 0) from the origin, `turns` times.
PathSegment circle(double radius_mm, int turns, double feed) {
    PathSegment s = feed_to(0, feed, 0);
    s.kind = SegmentKind::Arc;
    s.centre_mm = {radius_mm, 0};
    s.turns = turns;
    return s;
}

}  // namespace

std::vector<PreparedSegment> plan(const PlannerConfig& cfg, const std::vector<PathSegment>& moves) {
    std::vector<PreparedSegment> recs;
    Planner p(cfg, {});
    PreparedSegment r;
    for (const PathSegment& m : moves) {
        p.push(m);
        while (p.pop(r)) recs.push_back(r);
    }
    p.finish();
    while (p.pop(r)) recs.push_back(r);
    return recs;
}

namespace {

struct Run {
    // From the request to the first period in which the path decelerates as the jerk limit
    // allows: its tangential acceleration falls by J dt / 4 in the period or its tangential jerk
    // is below -J / 2 (J the weakest axis's; the plan may already do so itself).
    double fall_s = -1;
    double done_s = -1;              // from the request to the rate at its goal (a hold: held)
    bool ok = true;                  // within the limits throughout
    double u_mm_s = 0, a_mm_s2 = 0;  // path speed and tangential acceleration at the request
};

}  // namespace

// The shortest stop of a path speed u0 with tangential acceleration a0 (a0 >= -sqrt(2 J u0))
// under |a| <= A, |j| <= J: jerk -J down to -ap, -ap held, jerk +J back to 0 at rest, with
// u0 + a0^2 / 2J = ap^2 / J + ap t2.
double shortest_stop_s(double u0, double a0, double acc, double jerk) {
    const double w = u0 + a0 * a0 / (2 * jerk);
    const double ap = std::min(acc, std::sqrt(jerk * w));
    const double t2 = ap < acc ? 0.0 : (w - acc * acc / jerk) / acc;
    return (a0 + ap) / jerk + t2 + ap / jerk;
}

namespace {

// Plays `recs` with the ring topped up to `ahead` records (0: all queued), sets override
// `before` from the start and, after `at` periods, override `after` (hold when after < 0).
Run play(const PlannerConfig& cfg, const std::vector<PreparedSegment>& recs, long at, double before,
         double after, std::size_t ahead = 0) {
    const std::size_t cap = ahead > 0 ? ahead : recs.size();
    SpscRing<PreparedSegment> ring(cap + 1);
    Sampler sampler(sampler_config(cfg), ring, AxisArray{});
    test::LimitCheck check(cfg.limits);
    std::size_t next = 0;
    MotionSample last{};
    auto step = [&] {
        while (ring.size() < cap && next < recs.size()) ring.try_push(recs[next++]);
        last = sampler.advance(1e-3);
        check(last, 1e-3);
    };
    sampler.set_feed_override(before);
    for (long n = 0; n < at; ++n) step();
    const bool hold = after < 0;
    if (hold)
        sampler.set_hold(true);
    else
        sampler.set_feed_override(after);
    const double goal = hold ? 0.0 : after;
    // Path speed, tangential acceleration and jerk of a sample.
    struct Tangential {
        double u = 0, a = 0, j = 0;
    };
    auto tangential = [](const MotionSample& m) {
        double u2 = 0, ua = 0, uj = 0;
        for (int k = 0; k < kAxes; ++k) {
            u2 += m.vel_mm_s[k] * m.vel_mm_s[k];
            ua += m.vel_mm_s[k] * m.acc_mm_s2[k];
            uj += m.vel_mm_s[k] * m.jerk_mm_s3[k];
        }
        const double u = std::sqrt(u2);
        return u > 0 ? Tangential{u, ua / u, uj / u} : Tangential{};
    };
    double jerk = 1e300;
    for (int k = 0; k < kAxes; ++k) jerk = std::min(jerk, cfg.limits.jerk_mm_s3[k]);
    Run out;
    Tangential before_t = tangential(last);
    out.u_mm_s = before_t.u;
    out.a_mm_s2 = before_t.a;
    for (long n = 1; n <= 20000 && !sampler.status().done; ++n) {
        step();
        const double rate = sampler.status().rate;
        const Tangential now = tangential(last);
        if (out.fall_s < 0 && (now.j < -jerk / 2 || now.a < before_t.a - jerk * 1e-3 / 4))
            out.fall_s = n * 1e-3;
        before_t = now;
        const bool there = hold       ? sampler.status().held
                           : goal > 1 ? rate > 1 + 1e-9
                                      : std::fabs(rate - goal) < 1e-9;
        if (there) {
            out.done_s = n * 1e-3;
            break;
        }
    }
    for (int n = 0; n < 50; ++n) step();  // and a little after
    out.ok = check.ok();
    return out;
}

struct Stats {
    double mean = 0, lo = 1e9, hi = 0;
    int n = 0, missing = 0;
    void add(double x) {
        if (x < 0) {
            ++missing;
            return;
        }
        mean = (mean * n + x) / (n + 1);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        ++n;
    }
    std::string text() const {
        if (n == 0) return "-";
        std::string s = fmt::format("{:.3f} ({:.3f}-{:.3f})", mean, lo, hi);
        if (missing) s += fmt::format(" [{} never]", missing);
        return s;
    }
};

bool g_ok = true;

// Holds (or steps) at every `step_ms` from `from_ms` to `to_ms`: mean and range of both times.
// line_limits: the recs are one straight line along X, so the axis limits are the path's and
// the excess over shortest_stop_s() is printed too.
void sweep(const std::string& name, const PlannerConfig& cfg,
           const std::vector<PreparedSegment>& recs, long from_ms, long to_ms, long step_ms,
           double before = 1, double after = -1, bool line_limits = false) {
    Stats fall, done, excess;
    int bad = 0;
    for (long at = from_ms; at <= to_ms; at += step_ms) {
        const Run run = play(cfg, recs, at, before, after);
        fall.add(run.fall_s);
        done.add(run.done_s);
        if (line_limits && run.done_s >= 0)
            excess.add(run.done_s - shortest_stop_s(run.u_mm_s, run.a_mm_s2,
                                                    cfg.limits.acc_mm_s2[0],
                                                    cfg.limits.jerk_mm_s3[0]));
        if (!run.ok) ++bad;
    }
    if (bad || done.missing) g_ok = false;
    fmt::print("| {} | {} | {} | {} |{}\n", name, fall.text(), done.text(),
               line_limits ? excess.text() : "",
               bad ? fmt::format(" LIMITS LEFT in {} runs", bad) : "");
}

void single(const std::string& name, const PlannerConfig& cfg,
            const std::vector<PreparedSegment>& recs, long at, std::size_t ahead = 0) {
    const Run run = play(cfg, recs, at, 1, -1, ahead);
    if (!run.ok || run.done_s < 0) g_ok = false;
    fmt::print("| {} | {} | {:.3f} | |{}\n", name,
               run.fall_s < 0 ? std::string("never") : fmt::format("{:.3f}", run.fall_s),
               run.done_s, run.ok ? "" : " LIMITS LEFT");
}

}  // namespace

int holds_main() {
    fmt::print(
        "| case | decelerating as the jerk allows after, s: mean (range) | at the goal after, s | "
        "the goal's time "
        "less the shortest jerk-limited stop, s |\n");
    fmt::print("|---|---|---|---|\n");
    for (double jerk : {1e4, 1e5}) {
        const PlannerConfig cfg = uniform(100, 1000, jerk);
        const auto line = plan(cfg, {feed_to(200, 100, 0)});
        const long accel_ms = reaches_ms(line, 100);
        sweep(fmt::format("J {:g}: hold every 5 ms of the acceleration from rest ({} ms)", jerk,
                          accel_ms),
              cfg, line, 5, accel_ms, 5, 1, -1, true);
        sweep(fmt::format("J {:g}: hold every 1 ms of its first 30 ms", jerk), cfg, line, 1, 30, 1,
              1, -1, true);
        single(fmt::format("J {:g}: hold from cruise at 100 mm/s", jerk), cfg, line, 500);
    }
    for (auto [radius, jerk] : {std::pair{5.0, 1e5}, std::pair{5.0, 1e4}, std::pair{2.0, 1e4}}) {
        const PlannerConfig cfg = uniform(100, 1000, jerk);
        single(fmt::format("J {:g}: hold on a circle R {:g} mm at its turning limit", jerk, radius),
               cfg, plan(cfg, {circle(radius, 6, 100)}), 700);
    }
    {
        const PlannerConfig cfg = line_arc_line_cfg(1e5);
        const auto recs = line_arc_line(cfg);
        const long end_ms = long(planned_s(recs) * 1000) - 200;
        sweep("line-arc-line (J 1e5), hold every 3 ms", cfg, recs, 1, end_ms, 3);
        sweep("the same, 100 % -> 30 %", cfg, recs, 1, end_ms, 3, 1, 0.3);
        sweep("the same, 40 % -> 100 % (speeding up: first column not meaningful)", cfg, recs, 1,
              end_ms, 3, 0.4, 1);
    }
    {
        const PlannerConfig cfg = uniform(100, 1000, 1e5);
        std::vector<PathSegment> moves;
        for (int i = 1; i <= 1500; ++i) moves.push_back(feed_to(i * 0.2, 100, i));
        single("J 1e5: hold from 100 mm/s, two 0.2 mm records queued", cfg, plan(cfg, moves), 1500,
               2);
    }
    {
        const PlannerConfig cfg = uniform(100, 1000, 1e4);
        std::vector<PathSegment> moves;
        for (int i = 1; i <= 300; ++i) moves.push_back(feed_to(i * 1.0, 100, i));
        single("J 1e4: hold from 100 mm/s, five 1 mm records queued", cfg, plan(cfg, moves), 1500,
               5);
    }
    fmt::print("{}\n", g_ok ? "all runs within the limits" : "FAILED: limits left or never held");
    return g_ok ? 0 : 1;
}

long reaches_ms(const std::vector<motion::PreparedSegment>& recs, double v_mm_s) {
    double start = 0;
    for (const motion::PreparedSegment& r : recs) {
        for (double t = 0; t < r.profile.duration_s; t += 1e-4)
            if (r.profile.at(t).v_mm_s >= v_mm_s * (1 - 1e-6)) return long((start + t) * 1000);
        start += r.profile.duration_s;
    }
    return long(start * 1000);
}

PlannerConfig line_arc_line_cfg(double jerk) {
    PlannerConfig cfg = uniform(100, 1000, jerk);
    cfg.limits.acc_mm_s2[1] = 600;
    cfg.limits.jerk_mm_s3[1] = 0.4 * jerk;
    return cfg;
}

std::vector<PreparedSegment> line_arc_line(const PlannerConfig& cfg) {
    PathSegment arc = feed_to(0, 80, 1);
    arc.end_mm = {50, 10};
    arc.kind = SegmentKind::Arc;
    arc.centre_mm = {40, 10};
    arc.tolerance_mm = 0.01;
    PathSegment up = feed_to(50, 80, 2);
    up.end_mm[1] = 40;
    return plan(cfg, {feed_to(40, 80, 0), arc, up});
}

double planned_s(const std::vector<PreparedSegment>& recs) {
    double t = 0;
    for (const PreparedSegment& r : recs) t += r.profile.duration_s;
    return t;
}

}  // namespace sampler_holds
