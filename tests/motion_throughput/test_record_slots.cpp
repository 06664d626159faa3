// The planner builds each record in a slot it does not clear first (Planner::RecordSlot): every
// member must be written. Slots are reused after reset() (and once the consumer has taken every
// record), so a member emit() forgot would keep the value of the record planned there before.
// These tests plan long jerk-limited moves (seven-phase profiles, program_end on the last), then
// short ones into the same slots, and check each record against what a cleared record with the
// same plan holds.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "motion/planner.hpp"

namespace motion {
namespace {

PlannerConfig jerk_config() {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(200);
    cfg.limits.acc_mm_s2.fill(1000);
    cfg.limits.jerk_mm_s3.fill(1e5);
    return cfg;
}

PathSegment line_to(double x_mm, double y_mm, double feed_mm_s, std::int32_t line) {
    PathSegment s;
    s.end_mm[0] = x_mm;
    s.end_mm[1] = y_mm;
    s.feed_mm_s = feed_mm_s;
    s.tolerance_mm = 0.05;
    s.line = line;
    s.move_id = static_cast<std::uint32_t>(line);
    return s;
}

// Long moves at full feed: acceleration-limited ramps, seven phases each.
std::vector<PathSegment> long_moves() {
    return {line_to(100, 0, 150, 1), line_to(100, 100, 150, 2), line_to(0, 100, 150, 3)};
}

// Short, slow moves: ramps that never reach full acceleration, fewer phases.
std::vector<PathSegment> short_moves() {
    return {line_to(0.05, 0, 5, 11), line_to(0.05, 0.05, 5, 12), line_to(0.2, 0.05, 5, 13),
            line_to(0.2, 0.3, 5, 14)};
}

std::vector<PreparedSegment> plan(Planner& planner, const std::vector<PathSegment>& moves) {
    std::vector<PreparedSegment> out;
    for (const PathSegment& s : moves) planner.push(s);
    planner.finish();
    while (const PreparedSegment* r = planner.pop_ref()) out.push_back(*r);
    return out;
}

bool same_bits(double a, double b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Every member but the padding, bit for bit.
void expect_same_record(const PreparedSegment& got, const PreparedSegment& want, std::size_t i) {
    SCOPED_TRACE(testing::Message() << "record " << i);
    const Element& g = got.geom;
    const Element& w = want.geom;
    EXPECT_EQ(g.kind, w.kind);
    EXPECT_TRUE(same_bits(g.length_mm, w.length_mm));
    for (int k = 0; k < kAxes; ++k) {
        EXPECT_TRUE(same_bits(g.origin[k], w.origin[k]) && same_bits(g.a[k], w.a[k]) &&
                    same_bits(g.b[k], w.b[k]) && same_bits(g.c[k], w.c[k]) &&
                    same_bits(g.end[k], w.end[k]))
            << "axis " << k;
    }
    EXPECT_TRUE(same_bits(g.radius_mm, w.radius_mm) && same_bits(g.theta0_rad, w.theta0_rad) &&
                same_bits(g.sweep_rad, w.sweep_rad));
    EXPECT_EQ(got.profile.count, want.profile.count);
    for (int p = 0; p < kMaxPhases; ++p) {  // the unused phases too: a cleared record's are 0
        const ProfilePhase& a = got.profile.phases[p];
        const ProfilePhase& b = want.profile.phases[p];
        EXPECT_TRUE(same_bits(a.t0_s, b.t0_s) && same_bits(a.s0_mm, b.s0_mm) &&
                    same_bits(a.v0_mm_s, b.v0_mm_s) && same_bits(a.a0_mm_s2, b.a0_mm_s2) &&
                    same_bits(a.j_mm_s3, b.j_mm_s3))
            << "phase " << p;
        EXPECT_TRUE(same_bits(got.phase_rate_cap[p], want.phase_rate_cap[p])) << "phase " << p;
    }
    EXPECT_TRUE(same_bits(got.profile.duration_s, want.profile.duration_s));
    EXPECT_TRUE(same_bits(got.profile.peak_v_mm_s, want.profile.peak_v_mm_s));
    EXPECT_TRUE(same_bits(got.profile.peak_a_mm_s2, want.profile.peak_a_mm_s2));
    EXPECT_TRUE(same_bits(got.profile.peak_j_mm_s3, want.profile.peak_j_mm_s3));
    EXPECT_EQ(got.line, want.line);
    EXPECT_EQ(got.seq, want.seq);
    EXPECT_EQ(got.rapid, want.rapid);
    EXPECT_EQ(got.program_end, want.program_end);
    EXPECT_EQ(got.rough, want.rough);
    EXPECT_EQ(got.action.kind, want.action.kind);
    EXPECT_EQ(got.action.flag, want.action.flag);
    EXPECT_EQ(got.action.value, want.action.value);
    EXPECT_TRUE(same_bits(got.action.number, want.action.number));
    EXPECT_EQ(got.dout_set, want.dout_set);
    EXPECT_EQ(got.dout_clear, want.dout_clear);
    EXPECT_EQ(got.message, want.message);
    EXPECT_EQ(got.move_id, want.move_id);
    for (int k = 0; k < kProbeAxes; ++k) {
        EXPECT_EQ(got.probe[k].input, want.probe[k].input) << "probe " << k;
        EXPECT_EQ(got.probe[k].level, want.probe[k].level) << "probe " << k;
        EXPECT_TRUE(same_bits(got.probe[k].speed_mm_s, want.probe[k].speed_mm_s));
        EXPECT_TRUE(same_bits(got.probe[k].travel_mm, want.probe[k].travel_mm));
    }
}

// What the record must hold: the planned values, every other member as in a cleared record.
PreparedSegment cleared_with_plan_of(const PreparedSegment& r) {
    PreparedSegment want{};
    want.geom = r.geom;
    want.profile.count = r.profile.count;
    for (int p = 0; p < r.profile.count; ++p) {
        want.profile.phases[p] = r.profile.phases[p];
        want.phase_rate_cap[p] = r.phase_rate_cap[p];
    }
    want.profile.duration_s = r.profile.duration_s;
    want.profile.peak_v_mm_s = r.profile.peak_v_mm_s;
    want.profile.peak_a_mm_s2 = r.profile.peak_a_mm_s2;
    want.profile.peak_j_mm_s3 = r.profile.peak_j_mm_s3;
    want.line = r.line;
    want.seq = r.seq;
    want.rapid = r.rapid;
    want.program_end = r.program_end;
    want.rough = r.rough;
    want.move_id = r.move_id;
    return want;
}

TEST(RecordSlots, ReusedSlotsKeepNothingOfTheRecordsBefore) {
    const PlannerConfig cfg = jerk_config();
    Planner fresh(cfg, AxisArray{});
    const std::vector<PreparedSegment> want = plan(fresh, short_moves());

    Planner reused(cfg, AxisArray{});
    const std::vector<PreparedSegment> before = plan(reused, long_moves());
    // The slots must have held something to forget: longer profiles, and a program end in a
    // slot that now holds a record before the last.
    ASSERT_LT(before.size(), want.size());
    ASSERT_TRUE(before.back().program_end);
    int longer = 0;
    for (std::size_t i = 0; i < before.size(); ++i)
        longer += before[i].profile.count > want[i].profile.count;
    ASSERT_GT(longer, 0);

    reused.reset(AxisArray{});
    const std::vector<PreparedSegment> got = plan(reused, short_moves());
    ASSERT_EQ(got.size(), want.size());
    ASSERT_TRUE(got.back().program_end);
    for (std::size_t i = 0; i < got.size(); ++i) {
        PreparedSegment expected = cleared_with_plan_of(want[i]);
        // reset() does not restart the running number.
        expected.seq = got[i].seq;
        expect_same_record(got[i], expected, i);
        if (i > 0) {
            EXPECT_EQ(got[i].seq, got[i - 1].seq + 1);
        }
    }
}

TEST(RecordSlots, FreshRecordsAreWrittenWhole) {
    Planner planner(jerk_config(), AxisArray{});
    const std::vector<PreparedSegment> got = plan(planner, long_moves());
    ASSERT_FALSE(got.empty());
    for (std::size_t i = 0; i < got.size(); ++i)
        expect_same_record(got[i], cleared_with_plan_of(got[i]), i);
}

}  // namespace
}  // namespace motion
