// Test support shared by the sampler tests (tests/motion) and bench_sampler --holds
// (tests/bench_sampler): uniform machine limits, a straight X move, and the per-period limit
// check every jerk-limited rate-change run is held to.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include "motion/planner.hpp"
#include "motion/sampler.hpp"

namespace motion::test {

inline PlannerConfig uniform(double v, double a, double j) {
    PlannerConfig cfg;
    cfg.limits.vel_mm_s.fill(v);
    cfg.limits.acc_mm_s2.fill(a);
    cfg.limits.jerk_mm_s3.fill(j);
    return cfg;
}

// A feed move along X to `x` (the other axes at 0).
inline PathSegment feed_to(double x, double feed, std::int32_t line) {
    PathSegment s;
    s.end_mm = {x};
    s.feed_mm_s = feed;
    s.line = line;
    return s;
}

// Every period: analytic velocity, acceleration and jerk, and the finite differences of the
// sampled position (acceleration) and acceleration (jerk), within the limits (1e-6 relative).
class LimitCheck {
  public:
    explicit LimitCheck(const AxisLimits& lim) : lim_(lim) {}
    // Empty, or the first problem seen.
    const std::string& first() const { return first_; }
    bool ok() const { return first_.empty(); }
    void operator()(const MotionSample& s, double dt) {
        const double rel = 1 + 1e-6;
        for (int k = 0; k < kAxes && first_.empty(); ++k) {
            const double a_fd = n_ >= 2 ? (s.pos_mm[k] - 2 * p1_[k] + p2_[k]) / (dt * dt) : 0;
            const double j_fd = n_ >= 1 ? (s.acc_mm_s2[k] - a1_[k]) / dt : 0;
            const bool jerk = lim_.jerk_mm_s3[k] > 0;
            const char* what = std::fabs(s.vel_mm_s[k]) > lim_.vel_mm_s[k] * rel ? "velocity"
                               : std::fabs(s.acc_mm_s2[k]) > lim_.acc_mm_s2[k] * rel ? "acceleration"
                               : std::fabs(a_fd) > lim_.acc_mm_s2[k] * rel + 1e-4 ? "sampled acceleration"
                               : jerk && std::fabs(s.jerk_mm_s3[k]) > lim_.jerk_mm_s3[k] * rel
                                   ? "jerk"
                               : jerk && std::fabs(j_fd) > lim_.jerk_mm_s3[k] * rel + 1e-3
                                   ? "sampled jerk"
                                   : nullptr;
            if (what)
                first_ = "period " + std::to_string(n_) + " axis " + std::to_string(k) + ": " + what +
                         " (a " + std::to_string(s.acc_mm_s2[k]) + ", j " +
                         std::to_string(s.jerk_mm_s3[k]) + ", j_fd " + std::to_string(j_fd) + ")";
        }
        p2_ = p1_;
        p1_ = s.pos_mm;
        a1_ = s.acc_mm_s2;
        ++n_;
    }

  private:
    AxisLimits lim_;
    AxisArray p1_{}, p2_{}, a1_{};
    long n_ = 0;
    std::string first_;
};

}  // namespace motion::test
