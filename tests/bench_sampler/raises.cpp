// bench_sampler --raises: how soon a jerk-limited feed-override increase takes effect. The
// override is raised at every point of a grid over a plan (a straight line from rest to cruise,
// a line - quarter arc - line plan) from several rates to several targets, at two jerk limits.
// 1 ms periods on a simulated clock, so the figures do not depend on the machine or its load.
// Every period of every run is checked against the axis limits (the tests' LimitCheck,
// tests/motion/sampler_support.hpp).
//
// Per raise:
// - "rising after": from the request to the first period in which the rate's own part of the
//   path acceleration, v r' (v the planned speed), reaches J dt / 8 on average over the period
//   (what r'' at a quarter of the jerk gives in the first period from r' = 0; J the weakest
//   axis's), or, where the plan barely moves (v r' stays small however fast r rises), r rises
//   by 1 % of the step in one period, or the rate is at its target;
// - "there after": from the request to the rate at its target;
// - jerk reversals: periods in which the path's jerk turned from above J / 4 to below -J / 4
//   or back, from the request to the target (a smoothness figure: each is a jerk step of at
//   least J / 2 from one period to the next);
// - on the straight line, a lower bound for "there" (lower_bound_s()) and the excess over it,
//   also apart for the raises whose rate meets the plan in its cruise, where the bound is the
//   time-optimal jerk-limited speed change and so close to what is possible; earlier it only
//   knows the speed has to catch up, not that the acceleration has to meet the plan's too,
//   and is loose.
#include "raises.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "holds.hpp"
#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "sampler_support.hpp"

namespace sampler_raises {
namespace {

using namespace motion;
using test::feed_to;
using test::uniform;

constexpr double kDt_s = 1e-3;

// The plan of a straight X move from the origin, as planned speed against position.
struct LineTable {
    std::vector<double> s_mm, v_mm_s;
    double decel_from_mm = 0;  // where the plan's speed last is at its top (the final stop begins)
    double top_mm_s = 0;
};

LineTable line_table(const std::vector<PreparedSegment>& recs) {
    LineTable t;
    double start_mm = 0, top = 0;
    for (const PreparedSegment& r : recs) {
        for (double tt = 0; tt < r.profile.duration_s; tt += 1e-5) {
            const PathState ps = r.profile.at(tt);
            t.s_mm.push_back(start_mm + ps.s_mm);
            t.v_mm_s.push_back(ps.v_mm_s);
            top = std::max(top, ps.v_mm_s);
        }
        start_mm += r.profile.at(r.profile.duration_s).s_mm;
    }
    for (std::size_t i = 0; i < t.s_mm.size(); ++i)
        if (t.v_mm_s[i] >= top * (1 - 1e-9)) t.decel_from_mm = t.s_mm[i];
    t.top_mm_s = top;
    return t;
}

// A lower bound on the time from the request until the rate is at c (<= 1) to stay,
// for a straight line whose planned speed does not fall between s0 and the meeting point,
// from the commanded position s0, speed u0 and acceleration a0 at the request under |a| <= A,
// |jerk| <= J (the path is the axis). At the rate c the commanded speed is c v_p(s) at the
// position s it has reached. Any motion with a <= A has u(s)^2 <= u0^2 + 2 A (s - s0) =
// um(s)^2, so it cannot meet c v_p before s*, the first s where c v_p(s) <= um(s), and it
// needs at least the time um takes to get there, (um(s*) - u0) / A. With a(t) <= a0 + J t as
// well, u(t) <= U(t) = u0 + the integral of min(A, a0 + J t); at the meeting u = c v_p(s_m) >=
// c v_p(s*) (the plan's speed does not fall there), so it needs at least the time U takes to
// reach that. The larger of the two; -1 where the table gives no s*.
struct Bound {
    double s = -1;        // the bound; -1: none
    bool cruise = false;  // met in the cruise: the jerk-limited change bound applies
};
Bound lower_bound_s(const LineTable& p, double s0, double u0, double a0, double c, double A,
                    double J) {
    std::size_t i = 0;
    while (i < p.s_mm.size() && p.s_mm[i] < s0) ++i;
    for (; i < p.s_mm.size(); ++i) {
        const double um = std::sqrt(u0 * u0 + 2 * A * (p.s_mm[i] - s0));
        if (c * p.v_mm_s[i] <= um) break;
    }
    if (i == p.s_mm.size() || p.s_mm[i] > p.decel_from_mm) return {};
    const double um = std::sqrt(u0 * u0 + 2 * A * (p.s_mm[i] - s0));
    const double t_phase = (um - u0) / A;
    const double goal = c * p.v_mm_s[i];
    const double t1 = std::max(0.0, (A - a0) / J);
    const double u1 = u0 + a0 * t1 + J * t1 * t1 / 2;
    double t_jerk = 0;
    if (goal <= u0) {
        t_jerk = 0;
    } else if (goal <= u1) {
        t_jerk = (-a0 + std::sqrt(a0 * a0 + 2 * J * (goal - u0))) / J;
    } else {
        t_jerk = t1 + (goal - u1) / A;
    }
    Bound bound{std::max(t_phase, t_jerk), false};
    // Met in the cruise (the plan's top speed there, a = 0): the rate then stays at c with
    // r' = 0, so the commanded motion has to get from (u0, a0) to (goal, 0), which takes at
    // least the time-optimal jerk-limited change: jerk +J to the peak ap (held at A if
    // reached), jerk -J back to 0.
    if (p.v_mm_s[i] >= p.top_mm_s * (1 - 1e-9) && a0 >= 0 && a0 * a0 / (2 * J) <= goal - u0) {
        const double du = goal - u0;
        const double ap = std::sqrt(J * du + a0 * a0 / 2);
        double t_cruise = 0;
        if (ap <= A) {
            t_cruise = (ap - a0) / J + ap / J;
        } else {
            const double t2 = (du - (2 * A * A - a0 * a0) / (2 * J)) / A;
            t_cruise = (A - a0) / J + t2 + A / J;
        }
        bound = {std::max(bound.s, t_cruise), true};
    }
    return bound;
}

struct Rise {
    double start_s = -1;  // rising after
    double done_s = -1;   // at the target after
    bool ok = true;       // within the limits throughout
    int reversals = 0;    // periods whose path jerk turned from above J / 4 to below -J / 4 or back
    double s0 = 0, u0 = 0, a0 = 0;
};

// Plays all of `recs` (all queued) at override `before`; after `at` periods sets `after`.
Rise play(const PlannerConfig& cfg, const std::vector<PreparedSegment>& recs, long at,
          double before, double after) {
    SpscRing<PreparedSegment> ring(recs.size() + 1);
    for (const PreparedSegment& r : recs) ring.try_push(r);
    Sampler sampler(sampler_config(cfg), ring, AxisArray{});
    test::LimitCheck check(cfg.limits);
    MotionSample last{};
    auto step = [&] {
        last = sampler.advance(kDt_s);
        check(last, kDt_s);
    };
    sampler.set_feed_override(before);
    for (long n = 0; n < at; ++n) step();
    Rise out;
    out.s0 = last.pos_mm[0];
    out.u0 = last.vel_mm_s[0];
    out.a0 = last.acc_mm_s2[0];
    double jerk = 1e300;
    for (int k = 0; k < kAxes; ++k) jerk = std::min(jerk, cfg.limits.jerk_mm_s3[k]);
    sampler.set_feed_override(after);
    double r_prev = sampler.status().rate;
    auto speed = [](const MotionSample& m) {
        double u2 = 0;
        for (int k = 0; k < kAxes; ++k) u2 += m.vel_mm_s[k] * m.vel_mm_s[k];
        return std::sqrt(u2);
    };
    auto path_jerk = [&](const MotionSample& m) {
        const double u = speed(m);
        double uj = 0;
        for (int k = 0; k < kAxes; ++k) uj += m.vel_mm_s[k] * m.jerk_mm_s3[k];
        return u > 0 ? uj / u : 0.0;
    };
    double j_prev = path_jerk(last);
    for (long n = 1; n <= 20000 && !sampler.status().done; ++n) {
        step();
        const double rate = sampler.status().rate;
        const bool there = rate >= after - 1e-9;
        const double v = rate > 0 ? speed(last) / rate : 0;
        const double j_now = path_jerk(last);
        if ((j_prev > jerk / 4 && j_now < -jerk / 4) || (j_prev < -jerk / 4 && j_now > jerk / 4))
            ++out.reversals;
        j_prev = j_now;
        if (out.start_s < 0 && (there || v * (rate - r_prev) / kDt_s >= jerk * kDt_s / 8 ||
                                rate - r_prev >= 0.01 * (after - before)))
            out.start_s = n * kDt_s;
        r_prev = rate;
        if (there) {
            out.done_s = n * kDt_s;
            break;
        }
    }
    for (int n = 0; n < 50; ++n) step();  // and a little after
    out.ok = check.ok();
    return out;
}

struct Stats {
    double mean = 0, lo = 1e9, hi = -1e9;
    long hi_at_ms = 0;  // the request with the largest value
    int n = 0, missing = 0;
    void add(double x, long at_ms) {
        mean = (mean * n + x) / (n + 1);
        lo = std::min(lo, x);
        if (x > hi) hi_at_ms = at_ms;
        hi = std::max(hi, x);
        ++n;
    }
    std::string text(bool where = false) const {
        if (n == 0) return missing ? fmt::format("never ({})", missing) : "-";
        std::string s = fmt::format("{:.3f} ({:.3f}-{:.3f}{})", mean, lo, hi,
                                    where ? fmt::format(" at {} ms", hi_at_ms) : "");
        if (missing) s += fmt::format(" [{} never]", missing);
        return s;
    }
};

struct Verdict {
    bool ok = true;
    double worst_start_s = 0;
};

// Raises from `before` to `after` at every `step_ms` of wall time in [from_ms, to_ms]; with a
// line table, the lower bound and the excess over it too.
void sweep(const std::string& name, const PlannerConfig& cfg,
           const std::vector<PreparedSegment>& recs, long from_ms, long to_ms, long step_ms,
           double before, double after, const LineTable* line, Verdict& verdict) {
    Stats start, done, bound, excess, excess_cruise, reversals;
    int bad = 0, count = 0;
    for (long at = from_ms; at <= to_ms; at += step_ms) {
        const Rise run = play(cfg, recs, at, before, after);
        ++count;
        if (run.start_s < 0) {
            ++start.missing;
        } else {
            start.add(run.start_s, at);
            verdict.worst_start_s = std::max(verdict.worst_start_s, run.start_s);
        }
        if (run.done_s < 0) {
            ++done.missing;
        } else {
            done.add(run.done_s, at);
        }
        if (line && run.done_s >= 0 && after <= 1) {
            const Bound b = lower_bound_s(*line, run.s0, run.u0, run.a0, after,
                                          cfg.limits.acc_mm_s2[0], cfg.limits.jerk_mm_s3[0]);
            const double lb = b.s;
            if (lb >= 0) {
                bound.add(lb, at);
                excess.add(run.done_s - lb, at);
                if (b.cruise) excess_cruise.add(run.done_s - lb, at);
                if (run.done_s < lb - 1e-3) {  // the bound is wrong, or the limits were left
                    fmt::print("  bound above the run at {} ms: {:.4f} < {:.4f}\n", at, run.done_s,
                               lb);
                    verdict.ok = false;
                }
            }
        }
        reversals.add(run.reversals, at);
        if (!run.ok) ++bad;
    }
    if (bad || done.missing || start.missing) verdict.ok = false;
    fmt::print("| {} ({} raises) | {} | {} | {} | {} | {} | {:.1f} ({:g}) |{}\n", name, count,
               start.text(), done.text(true), bound.text(), excess.text(true),
               excess_cruise.n ? fmt::format("{} ({})", excess_cruise.text(true), excess_cruise.n)
                               : std::string("-"),
               reversals.mean, reversals.hi,
               bad ? fmt::format(" LIMITS LEFT in {} runs", bad) : "");
}

}  // namespace

int raises_main(const Options& opt) {
    fmt::print(
        "| case | rising after, s: mean (range) | at the target after, s | lower bound, s | "
        "after less the bound, s | the same where the rate meets the plan in its cruise (raises) "
        "| path jerk reversals per raise: mean (most) |\n");
    fmt::print("|---|---|---|---|---|---|---|\n");
    Verdict verdict;
    const std::vector<double> jerks =
        opt.short_grid ? std::vector<double>{1e4} : std::vector<double>{1e4, 1e5};
    for (double jerk : jerks) {
        const PlannerConfig cfg = uniform(100, 1000, jerk);
        const auto line = sampler_holds::plan(cfg, {feed_to(200, 100, 0)});
        const LineTable table = line_table(line);
        const long accel_ms = sampler_holds::reaches_ms(line, 100);
        struct Step {
            double before, after;
        };
        const std::vector<Step> steps =
            opt.short_grid ? std::vector<Step>{{0.4, 1}}
                           : std::vector<Step>{{0.4, 1}, {0.1, 1}, {0.7, 1}, {0.9, 1}, {0.4, 0.8}};
        const long every = opt.short_grid ? 10 : 5;
        for (const Step& st : steps) {
            // Over the acceleration from rest (at the `before` rate it lasts accel / before)
            // and 50 ms of cruise.
            const long to_ms = long(accel_ms / st.before) + 50;
            sweep(fmt::format("J {:g}: line, {:g} % -> {:g} %, every {} ms of the first {} ms",
                              jerk, st.before * 100, st.after * 100, every, to_ms),
                  cfg, line, every, to_ms, every, st.before, st.after, &table, verdict);
        }
        if (!opt.short_grid) {
            const auto slow = sampler_holds::plan(cfg, {feed_to(200, 80, 0)});
            const long to_ms = sampler_holds::reaches_ms(slow, 80) + 50;
            sweep(fmt::format("J {:g}: line at 80 mm/s, 100 % -> 120 %, every 5 ms of the first "
                              "{} ms",
                              jerk, to_ms),
                  cfg, slow, 5, to_ms, 5, 1, 1.2, nullptr, verdict);
        }
        const PlannerConfig lal_cfg = sampler_holds::line_arc_line_cfg(jerk);
        const auto lal = sampler_holds::line_arc_line(lal_cfg);
        // At 40 % the plan takes 2.5 times as long; raises over the first 80 % of that.
        const long lal_to_ms = long(sampler_holds::planned_s(lal) / 0.4 * 1000 * 0.8);
        const long lal_every = opt.short_grid ? 9 : 3;
        sweep(fmt::format("J {:g}: line-arc-line, 40 % -> 100 %, every {} ms of the first {} ms",
                          jerk, lal_every, lal_to_ms),
              lal_cfg, lal, 1, lal_to_ms, lal_every, 0.4, 1, nullptr, verdict);
        if (!opt.short_grid)
            sweep(fmt::format("J {:g}: line-arc-line, 10 % -> 100 %, every 7 ms of the first {} ms",
                              jerk, lal_to_ms * 4),
                  lal_cfg, lal, 1, lal_to_ms * 4, 7, 0.1, 1, nullptr, verdict);
    }
    fmt::print("worst rising after: {:.3f} s\n", verdict.worst_start_s);
    if (opt.max_start_ms > 0 && verdict.worst_start_s * 1000 > opt.max_start_ms + 1e-9) {
        fmt::print("FAILED: a raise started rising after more than {:g} ms\n", opt.max_start_ms);
        return 1;
    }
    fmt::print("{}\n", verdict.ok
                           ? "all runs within the limits"
                           : "FAILED: limits left, a raise never got there or a bound broken");
    return verdict.ok ? 0 : 1;
}

}  // namespace sampler_raises
