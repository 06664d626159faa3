// Property tests: the transform chain against matrices built independently with Eigen, and arc
// geometry invariants (start and end on the circle, centre where the definition puts it), over
// seeded random inputs so failures reproduce.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "block_builder.hpp"
#include "interp/arc.hpp"
#include "interp/executor.hpp"
#include "interp/transform.hpp"

namespace interp {
namespace {

constexpr double kPi = std::numbers::pi;

// Reference matrices written out element by element (not through rotation_about), so a sign or
// order mistake in the implementation cannot cancel itself here.
Eigen::Matrix4d ref_rotation(Plane p, const Eigen::Vector3d& c, double deg) {
    const double a = deg * kPi / 180, co = std::cos(a), si = std::sin(a);
    const PlaneAxes ax = plane_axes(p);
    Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
    r(ax.first, ax.first) = co;
    r(ax.first, ax.second) = -si;
    r(ax.second, ax.first) = si;
    r(ax.second, ax.second) = co;
    Eigen::Matrix4d t = Eigen::Matrix4d::Identity(), ti = Eigen::Matrix4d::Identity();
    t.block<3, 1>(0, 3) = c;
    ti.block<3, 1>(0, 3) = -c;
    return t * r * ti;
}

Eigen::Matrix4d ref_scale(const Eigen::Vector3d& c, const Eigen::Vector3d& f) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 3; ++i) {
        m(i, i) = f[i];
        m(i, 3) = c[i] - f[i] * c[i];
    }
    return m;
}

TEST(TransformProperty, RandomChainsMatchReferenceProducts) {
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> coord(-100, 100), angle(-360, 360), fac(0.1, 5);
    std::uniform_int_distribution<int> kind(0, 2), plane(0, 2), mask(1, 7);
    for (int trial = 0; trial < 500; ++trial) {
        ProgramTransform xf;
        Eigen::Matrix4d ref = Eigen::Matrix4d::Identity();
        const int n = 1 + trial % 8;
        for (int k = 0; k < n; ++k) {
            const Eigen::Vector3d c(coord(rng), coord(rng), coord(rng));
            switch (kind(rng)) {
                case 0: {
                    const Plane p = static_cast<Plane>(plane(rng));
                    const double a = angle(rng);
                    ASSERT_TRUE(xf.push_rotation(p, c, a));
                    ref = ref * ref_rotation(p, c, a);
                    break;
                }
                case 1: {
                    const Eigen::Vector3d f(fac(rng), fac(rng), fac(rng));
                    ASSERT_TRUE(xf.push_scale(c, f));
                    ref = ref * ref_scale(c, f);
                    break;
                }
                default: {
                    const unsigned m = static_cast<unsigned>(mask(rng));
                    Eigen::Vector3d f(1, 1, 1);
                    for (int i = 0; i < 3; ++i)
                        if (m & (1u << i)) f[i] = -1;
                    ASSERT_TRUE(xf.push_mirror(c, m));
                    ref = ref * ref_scale(c, f);
                }
            }
        }
        const Eigen::Vector3d p(coord(rng), coord(rng), coord(rng));
        const Eigen::Vector4d expect = ref * Eigen::Vector4d(p.x(), p.y(), p.z(), 1);
        const Eigen::Vector3d got = xf.apply(p);
        EXPECT_NEAR((got - expect.head<3>()).norm(), 0, 1e-6 * (1 + expect.norm()))
            << "trial " << trial;
        // The inverse brings the point back.
        EXPECT_NEAR((xf.inverse(got) - p).norm(), 0, 1e-6 * (1 + p.norm())) << "trial " << trial;
    }
}

TEST(TransformProperty, G69PopsTheMostRecentRotationOnly) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-50, 50), angle(-180, 180);
    for (int trial = 0; trial < 100; ++trial) {
        ProgramTransform xf;
        Eigen::Matrix4d keep = Eigen::Matrix4d::Identity();
        const Eigen::Vector3d c1(coord(rng), coord(rng), 0), c2(coord(rng), coord(rng), 0);
        const double a1 = angle(rng), a2 = angle(rng), s = 0.5;
        xf.push_rotation(Plane::XY, c1, a1);
        keep = keep * ref_rotation(Plane::XY, c1, a1);
        xf.push_scale(c2, Eigen::Vector3d(s, s, 1));
        keep = keep * ref_scale(c2, Eigen::Vector3d(s, s, 1));
        xf.push_rotation(Plane::XY, c2, a2);
        ASSERT_TRUE(xf.pop_rotation());
        const Eigen::Vector3d p(coord(rng), coord(rng), coord(rng));
        const Eigen::Vector4d expect = keep * Eigen::Vector4d(p.x(), p.y(), p.z(), 1);
        EXPECT_NEAR((xf.apply(p) - expect.head<3>()).norm(), 0, 1e-9);
    }
}

TEST(TransformProperty, MirrorClearRemovesOnlyTheListedAxes) {
    ProgramTransform xf;
    xf.push_mirror(Eigen::Vector3d(10, 20, 30), 7);
    xf.clear_mirror(1);  // X no longer mirrored
    const Eigen::Vector3d got = xf.apply(Eigen::Vector3d(1, 2, 3));
    EXPECT_NEAR(got.x(), 1, 1e-12);
    EXPECT_NEAR(got.y(), 38, 1e-12);
    EXPECT_NEAR(got.z(), 57, 1e-12);
    xf.clear_mirror(6);
    EXPECT_TRUE(xf.identity());
}

TEST(ArcProperty, RArcsHaveStartAndEndOnTheCircleAndTheRightSweep) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> coord(-100, 100), extra(0.001, 50);
    for (int trial = 0; trial < 2000; ++trial) {
        ArcInput in;
        in.start = {coord(rng), coord(rng)};
        in.end = {coord(rng), coord(rng)};
        in.ccw = trial % 2 == 0;
        const double half = (in.end - in.start).norm() / 2;
        const double r = half + extra(rng);
        const bool long_arc = trial % 3 == 0;
        in.radius = long_arc ? -r : r;
        ArcResult out;
        ASSERT_EQ(solve_arc(in, out), "") << trial;
        EXPECT_NEAR((in.start - out.centre).norm(), r, 1e-9 * (1 + r));
        EXPECT_NEAR((in.end - out.centre).norm(), r, 1e-9 * (1 + r));
        // R>0 is the short way (≤180°), R<0 the long way (>180°).
        if (long_arc)
            EXPECT_GE(out.sweep_rad, kPi - 1e-9);
        else
            EXPECT_LE(out.sweep_rad, kPi + 1e-9);
        // Walking the sweep from the start in the travel direction lands on the end point.
        const double a0 = std::atan2(in.start.y() - out.centre.y(), in.start.x() - out.centre.x());
        const double a1 = a0 + (in.ccw ? out.sweep_rad : -out.sweep_rad);
        const Eigen::Vector2d e = out.centre + r * Eigen::Vector2d(std::cos(a1), std::sin(a1));
        EXPECT_NEAR((e - in.end).norm(), 0, 1e-6 * (1 + r)) << trial;
    }
}

TEST(ArcProperty, CentreArcsKeepTheProgrammedCentre) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> coord(-100, 100), ang(-kPi, kPi), rad(0.01, 80);
    for (int trial = 0; trial < 2000; ++trial) {
        auto q9 = [](double v) { return std::stod(fmt::format("{:.9f}", v)); };
        const Eigen::Vector2d c(q9(coord(rng)), q9(coord(rng)));
        const double r = rad(rng), a0 = ang(rng), a1 = ang(rng);
        ArcInput in;
        in.start = c + r * Eigen::Vector2d(std::cos(a0), std::sin(a0));
        in.end = c + r * Eigen::Vector2d(std::cos(a1), std::sin(a1));
        in.centre = c;
        in.ccw = trial % 2 == 1;
        ArcResult out;
        ASSERT_EQ(solve_arc(in, out), "") << trial;
        EXPECT_NEAR((out.centre - c).norm(), 0, 1e-12);
        EXPECT_NEAR(out.radius_mm, r, 1e-9);
        double expect = in.ccw ? a1 - a0 : a0 - a1;
        while (expect <= 0) expect += 2 * kPi;
        if ((in.end - in.start).norm() < 1e-9) expect = 2 * kPi;
        EXPECT_NEAR(out.sweep_rad, expect, 1e-6) << trial;
    }
}

}  // namespace
}  // namespace interp

namespace interp {
namespace {

struct LastArc : CanonSink {
    std::optional<canon::Arc> arc;
    void emit(const Canon& c) override {
        if (const auto* a = std::get_if<canon::Arc>(&c.cmd)) arc = *a;
    }
};

// Arcs programmed under random rotations, uniform scalings and mirrors (all in G17) come out
// with the start and end on one circle about the transformed programmed centre, and with the
// direction flipped exactly when an odd number of plane mirrors is active.
TEST(ArcProperty, ArcsThroughTheExecutorUnderRandomTransforms) {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<double> coord(-50, 50), angle(-180, 180), fac(0.2, 3),
        rad(1, 30), ang(-kPi, kPi);
    std::uniform_int_distribution<int> kind(0, 2), coin(0, 1);
    for (int trial = 0; trial < 300; ++trial) {
        LastArc sink;
        Executor exec(sink, BackendConfig{});
        ProgramTransform ref;
        int mirrors = 0;
        auto run = [&](const std::string& line) { exec.execute(test::blk(line)); };
        run("G01 F100");
        // Values go through the program text, so the reference uses the printed values.
        auto q = [](double v) { return std::stod(fmt::format("{:.6f}", v)); };
        for (int k = 0; k < 3; ++k) {
            const double cx = q(coord(rng)), cy = q(coord(rng));
            switch (kind(rng)) {
                case 0: {
                    const double a = q(angle(rng));
                    run(fmt::format("G68 X{:.6f} Y{:.6f} R{:.6f}", cx, cy, a));
                    ref.push_rotation(Plane::XY, {cx, cy, 0}, a);
                    break;
                }
                case 1: {
                    const double f = q(fac(rng));
                    run(fmt::format("G51 X{:.6f} Y{:.6f} P{:.6f}", cx, cy, f));
                    ref.push_scale({cx, cy, 0}, {f, f, 1});
                    break;
                }
                default:
                    run(fmt::format("G51.1 X{:.6f}", cx));
                    ref.push_mirror({cx, 0, 0}, 1);
                    ++mirrors;
            }
        }
        // A circle in program coordinates, start and end on it.
        auto q9 = [](double v) { return std::stod(fmt::format("{:.9f}", v)); };
        const Eigen::Vector2d c(q9(coord(rng)), q9(coord(rng)));
        const double r = rad(rng), a0 = ang(rng), a1 = ang(rng);
        Eigen::Vector2d s = c + r * Eigen::Vector2d(std::cos(a0), std::sin(a0));
        Eigen::Vector2d e = c + r * Eigen::Vector2d(std::cos(a1), std::sin(a1));
        s = {q9(s.x()), q9(s.y())};
        e = {q9(e.x()), q9(e.y())};
        const bool ccw = coin(rng) == 1;
        run(fmt::format("G01 X{:.9f} Y{:.9f}", s.x(), s.y()));
        const Eigen::Vector3d start = ref.apply({s.x(), s.y(), 0});
        run(fmt::format("{} X{:.9f} Y{:.9f} I{:.9f} J{:.9f}", ccw ? "G03" : "G02", e.x(), e.y(),
                        c.x() - s.x(), c.y() - s.y()));
        ASSERT_TRUE(sink.arc) << trial;
        const canon::Arc& a = *sink.arc;
        const Eigen::Vector3d centre(a.centre_mm[0], a.centre_mm[1], a.centre_mm[2]);
        const Eigen::Vector3d end(a.end_mm[0], a.end_mm[1], a.end_mm[2]);
        EXPECT_NEAR((centre - ref.apply({c.x(), c.y(), 0})).norm(), 0, 1e-6) << trial;
        EXPECT_NEAR((end - ref.apply({e.x(), e.y(), 0})).norm(), 0, 1e-6) << trial;
        EXPECT_NEAR((start - centre).norm(), (end - centre).norm(), 1e-6) << trial;
        EXPECT_EQ(a.turns > 0, ccw != (mirrors % 2 == 1)) << trial;
        EXPECT_EQ(a.plane, Plane::XY);
    }
}

}  // namespace
}  // namespace interp
