// What the jerk-limited sampler trusts beyond the queued records (rate_fits_any_record(), used
// by Sampler::unknown_safe()): that no record the planner makes can be driven past an axis's
// limits by a rate move the function accepts. Two halves, each able to fail on its own:
// - the function against a brute force over every record the planner's guarantee allows;
// - the guarantee itself against records the planner really makes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "motion/planner.hpp"
#include "motion/sampler.hpp"
#include "program_gen.hpp"

namespace motion {
namespace {

// What the planner guarantees of every record at r = 1, per axis k: speed |Vel| <= vmax,
// |Acc| <= keep A, |Jrk| <= keep J with keep = 1 - reserve, and on a record next to a rough
// junction keep - junction_share, with the junction's step kept out of the axis's budget
// (junction_share r of A, junction_share r^2 of J, as the sampler's checks keep it). Scaled in
// time by a rate r the axis sees
//     velocity r Vel,  acceleration r^2 Acc + r' Vel,  jerk r^3 Jrk + 3 r r' Acc + r'' Vel,
// linear in (Vel, Acc, Jrk), so the corners of their ranges are the worst records. Returns the
// first record and rate that break a limit, or "".
std::string worst_record_breaks(const SamplerConfig& cfg, const RateSpan& box) {
    const double keep = 1 - cfg.override_reserve, js = cfg.junction_share;
    for (int k = 0; k < kAxes; ++k) {
        const double vmax = cfg.limits.vel_mm_s[k], amax = cfg.limits.acc_mm_s2[k];
        const double jmax = cfg.limits.jerk_mm_s3[k];
        for (bool rough : {false, true}) {
            const double acc_cap = (keep - (rough ? js : 0)) * amax;
            const double jerk_cap = (keep - (rough ? js : 0)) * jmax;
            for (int ir = 0; ir <= 8; ++ir) {
                const double r = box.r_lo + (box.r_hi - box.r_lo) * ir / 8;
                const double acc_budget = (1 - (rough ? js * r : 0)) * amax;
                const double jerk_budget = (1 - (rough ? js * r * r : 0)) * jmax;
                for (double vel : {-vmax, 0.0, vmax})
                    for (double acc : {-acc_cap, 0.0, acc_cap})
                        for (double jrk : {-jerk_cap, 0.0, jerk_cap})
                            for (double rd : {box.rd_lo, box.rd_hi}) {
                                const double a = r * r * acc + rd * vel;
                                const double j = r * r * r * jrk + 3 * r * rd * acc + box.rdd * vel;
                                const char* what =
                                    std::fabs(r * vel) > vmax * (1 + 1e-12)    ? "velocity"
                                    : std::fabs(a) > acc_budget * (1 + 1e-12)  ? "acceleration"
                                    : std::fabs(j) > jerk_budget * (1 + 1e-12) ? "jerk"
                                                                               : nullptr;
                                if (what)
                                    return std::string(what) + " on axis " + std::to_string(k) +
                                           (rough ? " (rough)" : "") + " at r " +
                                           std::to_string(r) + ", r' " + std::to_string(rd);
                            }
            }
        }
    }
    return "";
}

// Random limits, reserves and junction shares; rate boxes from r = 0 to just above 1, |r'| up
// to 1.5 A / V and |r''| up to 1.5 J / V of the weakest axis (well past what is safe). Every
// box the function accepts must be safe for every record the guarantee allows. Checked by
// editing the function, one edit at a time, each failing here: the rate taken at the box's low
// end instead of its high end, the 3 r Acc r' term dropped, the junction share dropped or
// halved (acceleration or jerk), the plan trusted to leave twice the reserve, the fixed
// bounds doubled, rates up to 1.01 let through. And it must not be vacuous: thousands of the
// boxes accepted lie beyond the fixed reserve bounds, where the rate's own fall makes room.
TEST(SamplerBeyondTheRing, RateFitsAnyRecordAcceptsNoMoveSomeRecordCannotTake) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u01(0, 1);
    int accepted = 0, beyond_fixed = 0;
    for (int n = 0; n < 40000; ++n) {
        SamplerConfig cfg;
        cfg.limits = test::random_limits(rng, true);
        cfg.override_reserve = std::array{0.01, 0.05, 0.1}[n % 3];
        cfg.junction_share = std::array{0.1, 0.05, 0.2}[n / 3 % 3];
        const RateLimits fixed = rate_limits(cfg);
        double vm = 1e9, am = 1e9;
        for (int k = 0; k < kAxes; ++k) {
            vm = std::min(vm, cfg.limits.acc_mm_s2[k] / cfg.limits.vel_mm_s[k]);
            am = std::min(am, cfg.limits.jerk_mm_s3[k] / cfg.limits.vel_mm_s[k]);
        }
        // Above 1 (nothing beyond the ring may be sped up) with r' and r'' small enough for
        // the fixed bounds, so that a rate cap above 1 would show as a speed over vmax.
        RateSpan box;
        const double pick = u01(rng);
        box.r_hi = pick < 0.1 ? 1.0 : pick < 0.2 ? 1 + 1e-3 * u01(rng) : u01(rng) * 1.02;
        box.r_lo = box.r_hi * u01(rng);
        const double scale = box.r_hi > 1 ? 0.01 : 1.5;
        const double a = (2 * u01(rng) - 1) * scale * vm * u01(rng);
        const double b = (2 * u01(rng) - 1) * scale * vm * u01(rng);
        box.rd_lo = std::min(a, b);
        box.rd_hi = std::max(a, b);
        box.rdd = (2 * u01(rng) - 1) * scale * am * u01(rng);
        if (!rate_fits_any_record(cfg, fixed, box)) continue;
        ++accepted;
        const double rd = std::max(std::fabs(box.rd_lo), std::fabs(box.rd_hi));
        if (rd > fixed.max_rate_per_s || std::fabs(box.rdd) > fixed.max_rate_per_s2) ++beyond_fixed;
        const std::string broken = worst_record_breaks(cfg, box);
        ASSERT_EQ(broken, "") << "box " << n << ": r [" << box.r_lo << ", " << box.r_hi << "], r' ["
                              << box.rd_lo << ", " << box.rd_hi << "], r'' " << box.rdd;
    }
    EXPECT_GT(beyond_fixed, 2000) << accepted;
}

// The guarantee the function rests on, against the planner: every record of random programs
// (lines, arcs, helices, blends, exact stops, rapids; jerk-limited, small and large windows)
// sampled at r = 1 keeps each axis's speed within vmax and its acceleration and jerk within
// (1 - reserve) of the limits, (1 - reserve - junction share) on a record next to a rough
// junction (the planner plans those records with that cut, Planner::add_item). If the planner
// ever used more, the function above would trust room that is not there. The largest values
// reach the cut itself (1.0000), so any planner that used more fails: checked by planning with
// half the reserve, and with half the junction share (jerk 1.004-1.056 of it).
TEST(SamplerBeyondTheRing, PlannedRecordsKeepWhatTheSamplerTrustsBeyondTheRing) {
    int records = 0, rough = 0;
    double worst_acc = 0, worst_jerk = 0;
    for (std::uint64_t seed = 1; seed <= 24; ++seed) {
        std::mt19937_64 rng(seed * 104729);
        const test::Program prog = test::random_program(rng, {30, true, seed % 3 == 0});
        PlannerConfig cfg;
        cfg.limits = test::random_limits(rng, true);
        const SamplerConfig sc = sampler_config(cfg);
        const double keep = 1 - sc.override_reserve;
        Planner planner(cfg, {});
        PreparedSegment rec;
        auto check = [&](const PreparedSegment& r) {
            if (r.action.kind != ActionKind::None || r.profile.duration_s <= 0) return;
            ++records;
            rough += r.rough;
            const double share = keep - (r.rough ? sc.junction_share : 0);
            const Profile1D& p = r.profile;
            for (int i = 0; i <= 200; ++i) {
                const double t = p.duration_s * i / 200;
                const MotionSample m = sample(r, t);
                for (int k = 0; k < kAxes; ++k) {
                    const double acc =
                        std::fabs(m.acc_mm_s2[k]) / (share * cfg.limits.acc_mm_s2[k]);
                    const double jerk =
                        std::fabs(m.jerk_mm_s3[k]) / (share * cfg.limits.jerk_mm_s3[k]);
                    worst_acc = std::max(worst_acc, acc);
                    worst_jerk = std::max(worst_jerk, jerk);
                    ASSERT_LE(std::fabs(m.vel_mm_s[k]), cfg.limits.vel_mm_s[k] * (1 + 1e-9))
                        << "seed " << seed << " line " << r.line << " axis " << k;
                    ASSERT_LE(acc, 1 + 1e-6) << "seed " << seed << " line " << r.line << " axis "
                                             << k << " rough " << r.rough << " t " << t;
                    ASSERT_LE(jerk, 1 + 1e-6) << "seed " << seed << " line " << r.line << " axis "
                                              << k << " rough " << r.rough << " t " << t;
                }
            }
        };
        for (const PathSegment& s : prog.segs) {
            planner.push(s);
            while (planner.pop(rec)) check(rec);
        }
        planner.finish();
        while (planner.pop(rec)) check(rec);
    }
    EXPECT_GT(records, 500);
    EXPECT_GT(rough, 20);
    std::printf("%d records (%d rough): largest |a| %.4f, |j| %.4f of what the sampler trusts\n",
                records, rough, worst_acc, worst_jerk);
}

}  // namespace
}  // namespace motion
