// The plan-time joint limit check (components/motion/joint_limits.hpp) against brute force:
// seeded random lines, arcs and helices through CoreXY and 5-axis TRT kinematics, with limits
// drawn close to where the joints really go. Brute force finds each joint's extreme over the
// path from 4000 samples refined by a golden-section search, so it does not share the check's
// sampling. The check must refuse exactly the moves that pass a limit by more than its bound
// (2e-6, in the header), name a real point of the path, and name the farthest one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "joint_limits.hpp"
#include "kins_link.hpp"
#include "motion/geometry.hpp"
#include "motion/kinematics.hpp"

namespace {

using motioncomp::JointLimitCheck;
using motioncomp::JointLimitConfig;
using motioncomp::PlanningKinematics;

constexpr double kBound = 2e-6 + 1e-9;  // the check's bound plus its rounding allowance

// The A axis 80 mm below the workpiece origin (configs/sim/5axis-trt.ini's geometry).
motion::TrtPivots trt_pivots() {
    motion::TrtPivots p;
    p.a_pivot_mm = Eigen::Vector3d(0, 0, -80);
    return p;
}

std::vector<double> joints_at(const motion::Kinematics& k, const motion::Element& e, double s) {
    std::vector<double> j(k.joint_count());
    k.inverse(motion::point_at(e, s), j);
    return j;
}

// The largest value of sign * joint n over s in (from, to], by sampling and refining.
double extreme(const motion::Kinematics& k, const motion::Element& e, std::size_t n, double sign,
               double from, double to) {
    auto f = [&](double s) { return sign * joints_at(k, e, s)[n]; };
    constexpr int kSamples = 4000;
    const double h = (to - from) / kSamples;
    double best = -INFINITY, best_s = to;
    for (int i = 1; i <= kSamples; ++i) {
        const double s = from + h * i;
        if (const double v = f(s); v > best) best = v, best_s = s;
    }
    double lo = std::max(from, best_s - h), hi = std::min(to, best_s + h);
    for (int i = 0; i < 100; ++i) {
        const double a = hi - 0.618034 * (hi - lo), b = lo + 0.618034 * (hi - lo);
        (f(a) > f(b) ? hi : lo) = f(a) > f(b) ? b : a;
    }
    return std::max(best, f(0.5 * (lo + hi)));
}

struct Machine {
    std::shared_ptr<const motion::Kinematics> kins;
    const char* name;
    bool rotary;  // moves A and C too
};

motion::AxisArray random_point(std::mt19937& rng, bool rotary) {
    std::uniform_real_distribution<double> xy(-150, 150), z(-100, 0), a(-60, 60), c(-200, 200);
    motion::AxisArray p{};
    p[0] = xy(rng);
    p[1] = xy(rng);
    p[2] = z(rng);
    if (rotary) {
        p[3] = a(rng);
        p[5] = c(rng);
    }
    return p;
}

// A line, or an arc or helix in XY (up to two turns) with the start's other axes moving too.
motion::Element random_move(std::mt19937& rng, const motion::AxisArray& start, bool rotary) {
    motion::AxisArray end = random_point(rng, rotary);
    if (std::uniform_int_distribution<int>(0, 1)(rng) == 0) return motion::make_line(start, end);
    std::uniform_real_distribution<double> r(5, 120), angle(0, 2 * std::numbers::pi);
    const double radius = r(rng), from = angle(rng), to = angle(rng);
    motion::PathSegment seg;
    seg.kind = motion::SegmentKind::Arc;
    seg.centre_mm = {start[0] - radius * std::cos(from), start[1] - radius * std::sin(from)};
    end[0] = seg.centre_mm[0] + radius * std::cos(to);
    end[1] = seg.centre_mm[1] + radius * std::sin(to);
    seg.end_mm = end;
    seg.turns = std::uniform_int_distribution<int>(1, 2)(rng) *
                (std::uniform_int_distribution<int>(0, 1)(rng) ? 1 : -1);
    return motion::make_arc(start, seg);
}

void check_random_moves(const Machine& m, unsigned seed, int moves) {
    std::mt19937 rng(seed);
    const std::size_t joints = m.kins->joint_count();
    std::uniform_real_distribution<double> offset(-1, 1), unit(0, 1);
    int refused = 0, cleared = 0;
    for (int i = 0; i < moves; ++i) {
        const motion::AxisArray start = random_point(rng, m.rotary);
        const motion::Element e = random_move(rng, start, m.rotary);
        const std::vector<double> j0 = joints_at(*m.kins, e, 0);
        // Limits just outside the joints' true extremes (by up to 1 mm, or half the time up to
        // 1e-4 mm), except one limit of one joint on every other move, moved by as much either
        // way, at most 0.5 mm inside the start: the check decides near the edge.
        JointLimitConfig cfg;
        std::vector<double> hi_true(joints), lo_true(joints);
        const auto tight = static_cast<std::size_t>(
            std::uniform_int_distribution<int>(0, static_cast<int>(2 * joints) - 1)(rng));
        const bool any_tight = i % 2 == 1;
        for (std::size_t n = 0; n < joints; ++n) {
            hi_true[n] = extreme(*m.kins, e, n, 1, 0, e.length_mm);
            lo_true[n] = -extreme(*m.kins, e, n, -1, 0, e.length_mm);
            const double scale = unit(rng) < 0.5 ? 1e-4 : 1.0;
            const double hi_off = any_tight && tight == 2 * n ? offset(rng) : unit(rng);
            const double lo_off = any_tight && tight == 2 * n + 1 ? -offset(rng) : -unit(rng);
            cfg.max_limit.push_back(std::max(hi_true[n] + scale * hi_off, j0[n] - 0.5));
            cfg.min_limit.push_back(std::min(lo_true[n] + scale * lo_off, j0[n] + 0.5));
        }
        auto make_copy = [&]() -> std::unique_ptr<motion::Kinematics> {
            if (m.rotary) return motion::make_kinematics("xyzac-trt", "", trt_pivots());
            return motion::make_kinematics("corexy", "");
        };
        cfg.kins = std::make_shared<PlanningKinematics>(nullptr, make_copy());
        JointLimitCheck check(cfg);
        const auto v = check.check(e);
        // What the check must decide: the end inside; other points no farther out than the
        // start (which may lie outside a limit: then the move may go back in).
        bool must_refuse = false, may_refuse = false;
        const std::vector<double> j1 = joints_at(*m.kins, e, e.length_mm);
        for (std::size_t n = 0; n < joints; ++n) {
            const double allow_hi = std::max(0.0, j0[n] - cfg.max_limit[n]);
            const double allow_lo = std::max(0.0, cfg.min_limit[n] - j0[n]);
            const double over_hi = hi_true[n] - cfg.max_limit[n] - allow_hi;
            const double over_lo = cfg.min_limit[n] - lo_true[n] - allow_lo;
            const double end_over = std::max(j1[n] - cfg.max_limit[n], cfg.min_limit[n] - j1[n]);
            must_refuse = must_refuse || over_hi > kBound || over_lo > kBound || end_over > 1e-9;
            may_refuse = may_refuse || over_hi > 1e-9 || over_lo > 1e-9 || end_over > 1e-9;
        }
        SCOPED_TRACE(::testing::Message()
                     << m.name << " seed " << seed << " move " << i
                     << (e.kind == motion::ElementKind::Arc ? " arc" : " line"));
        if (must_refuse) {
            EXPECT_TRUE(v.has_value());
        }
        if (!may_refuse) {
            EXPECT_FALSE(v.has_value());
        }
        if (!v) {
            ++cleared;
            continue;
        }
        ++refused;
        // A real point of the path, where that joint is where the message says, beyond its limit.
        const auto n = static_cast<std::size_t>(v->joint);
        std::vector<double> at(joints);
        m.kins->inverse(v->at_mm, at);
        EXPECT_NEAR(at[n], v->position, 1e-9);
        // The farthest beyond what the move was allowed: points before the end may be as far
        // out as the start.
        const double limit = v->above ? cfg.max_limit[n] : cfg.min_limit[n];
        const double sign = v->above ? 1 : -1;
        const double allow = std::max(0.0, sign * (j0[n] - limit));
        const double farthest = std::max(
            sign * ((v->above ? hi_true[n] : lo_true[n]) - limit) - allow, sign * (j1[n] - limit));
        const double reported = sign * (v->position - limit) -
                                (motion::point_at(e, e.length_mm) == v->at_mm ? 0 : allow);
        EXPECT_GT(reported, 0);
        EXPECT_NEAR(reported, farthest, 1e-6);
    }
    // Both verdicts were exercised.
    EXPECT_GT(refused, moves / 10);
    EXPECT_GT(cleared, moves / 10);
}

TEST(JointLimitSampling, CoreXYLinesAndArcsAgreeWithBruteForce) {
    check_random_moves({motion::make_kinematics("corexy", ""), "corexy", false}, 1, 300);
}

TEST(JointLimitSampling, TrtMovesTurningAAndCAgreeWithBruteForce) {
    check_random_moves({motion::make_kinematics("xyzac-trt", "", trt_pivots()), "xyzac-trt", true},
                       2, 300);
}

// The start's joints are taken from the last move's end when it starts there; a new tool
// offset must drop them (a TRT maps the same point to other joints).
TEST(JointLimitSampling, ToolOffsetChangeIsNotHiddenByTheRememberedEnd) {
    class Source final : public motion::KinematicsSource {
      public:
        std::unique_ptr<motion::Kinematics> make() const override {
            return std::make_unique<motion::XyzacTrtKinematics>(motion::TrtPivots{});
        }

      private:
        void copy_params_with_tool_offset(motion::Kinematics& k,
                                          double tool_mm) const noexcept override {
            motion::TrtPivots p;
            p.a_pivot_mm = Eigen::Vector3d(0, 0, -50 + tool_mm);
            static_cast<motion::XyzacTrtKinematics&>(k).set_pivots(p);
        }
    };
    auto source = std::make_shared<Source>();
    auto kins = source->make();
    source->refresh_with_tool_offset(*kins, 0);
    JointLimitConfig cfg;
    cfg.kins = std::make_shared<PlanningKinematics>(source, std::move(kins));
    // Joint 1 (machine Y) in [-10, 1e9]; the table tilted to A = 30 at workpiece (0, 0, 0).
    cfg.min_limit = {-1e9, -10, -1e9, -1e9, -1e9};
    cfg.max_limit = {1e9, 1e9, 1e9, 1e9, 1e9};
    JointLimitCheck check(cfg);
    motion::AxisArray tilted{};
    tilted[3] = 30;
    // Pivot 50 mm below: y = -50 sin 30 = -25 at A = 30: past -10 on the way.
    EXPECT_TRUE(check.check(motion::make_line({}, tilted)).has_value());
    // With a 45 mm tool the pivot is 5 mm below: y = -5 sin 30 = -2.5, inside; then a move in
    // X at that tilt starts where this one ended.
    check.set_tool_offset(45);
    ASSERT_FALSE(check.check(motion::make_line({}, tilted)).has_value());
    motion::AxisArray moved = tilted;
    moved[0] = 10;
    EXPECT_FALSE(check.check(motion::make_line(tilted, moved)).has_value());
    // Back to no tool (a program would not do this tilted; the check must still be right):
    // the start now maps to y = -25, outside, so a move back to A = 0 (y from -25 to 0) may
    // pass through -20. Taken from the remembered end (y = -2.5, inside) it would be refused.
    check.set_tool_offset(0);
    motion::AxisArray level = moved;
    level[3] = 0;
    EXPECT_FALSE(check.check(motion::make_line(moved, level)).has_value());
}

}  // namespace
