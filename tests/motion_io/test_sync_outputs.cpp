// Outputs synchronised with motion (M901 / LinuxCNC M62): they fall due in the period the
// sampler starts the record they ride on, without the path stopping there.
#include <gtest/gtest.h>

#include <cmath>

#include "motion/planner.hpp"
#include "motion/sampler.hpp"

namespace motion {
namespace {

PlannerConfig config() {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(100);
    cfg.limits.acc_mm_s2.fill(1000);
    return cfg;
}

PathSegment line_to(double x, double y, std::uint32_t id, double tol) {
    PathSegment s;
    s.end_mm = {x, y};
    s.feed_mm_s = 50;
    s.tolerance_mm = tol;
    s.line = static_cast<std::int32_t>(id);
    s.move_id = id;
    return s;
}

// Plans the moves; the first record of move `id` carries output 2 on (as the feeder does).
void load(SpscRing<PreparedSegment>& ring, const std::vector<PathSegment>& moves,
          std::uint32_t id) {
    Planner p(config(), {});
    for (const PathSegment& m : moves) p.push(m);
    p.finish();
    PreparedSegment r;
    bool marked = false;
    while (p.pop(r)) {
        if (!marked && r.move_id >= id) {
            r.dout_set = 1u << 2;
            marked = true;
        }
        ASSERT_TRUE(ring.try_push(r));
    }
    ASSERT_TRUE(marked);
}

struct Due {
    int period = -1;
    MotionSample before, at;
};

Due run_until_due(Sampler& sampler) {
    Due d;
    MotionSample last{};
    for (int n = 0; n < 100000 && !sampler.status().done; ++n) {
        const MotionSample s = sampler.advance(1e-3);
        const Sampler::SyncOutputs out = sampler.take_sync_outputs();
        if (out.set && d.period < 0) {
            EXPECT_EQ(out.set, 1u << 2);
            EXPECT_EQ(out.clear, 0u);
            d = {n, last, s};
        }
        last = s;
    }
    return d;
}

TEST(SyncOutputs, DueWhenTheNextCollinearMoveStartsAtFullSpeed) {
    SpscRing<PreparedSegment> ring(64);
    Sampler sampler(sampler_config(config()), ring, AxisArray{});
    load(ring, {line_to(10, 0, 1, 0.01), line_to(20, 0, 2, 0.01)}, 2);
    const Due d = run_until_due(sampler);
    ASSERT_GE(d.period, 0);
    // why: the period in which X passes 10, the end of move 1, and at 50 mm/s: no stop there.
    EXPECT_LT(d.before.pos_mm[0], 10);
    EXPECT_GE(d.at.pos_mm[0], 10);
    EXPECT_NEAR(d.at.vel_mm_s[0], 50, 1e-9);
}

TEST(SyncOutputs, RideOnTheBlendIntoTheNextMove) {
    SpscRing<PreparedSegment> ring(64);
    Sampler sampler(sampler_config(config()), ring, AxisArray{});
    load(ring, {line_to(10, 0, 1, 0.1), line_to(10, 10, 2, 0.1)}, 2);
    const Due d = run_until_due(sampler);
    ASSERT_GE(d.period, 0);
    // why: the corner at (10, 0) is rounded within 0.1 mm; the output comes where the blend
    // leaves the first line, before the corner and within a few tenths of a mm of it.
    const double to_corner = std::hypot(10 - d.at.pos_mm[0], d.at.pos_mm[1]);
    EXPECT_LT(d.before.pos_mm[1], 1e-12);
    EXPECT_LT(to_corner, 1.0);
    EXPECT_GT(std::hypot(d.at.vel_mm_s[0], d.at.vel_mm_s[1]), 1.0);  // moving through it
}

TEST(SyncOutputs, AbortDiscardsOutputsNotReached) {
    SpscRing<PreparedSegment> ring(64);
    Sampler sampler(sampler_config(config()), ring, AxisArray{});
    load(ring, {line_to(10, 0, 1, 0.01), line_to(20, 0, 2, 0.01)}, 2);
    for (int n = 0; n < 20; ++n) sampler.advance(1e-3);  // X ~0.2 mm at 18 mm/s
    sampler.abort();
    for (int n = 0; n < 2000; ++n) {
        sampler.advance(1e-3);
        EXPECT_EQ(sampler.take_sync_outputs().set, 0u);
    }
    EXPECT_TRUE(sampler.status().aborted);
}

}  // namespace
}  // namespace motion
