// shift_bezier_within() skips the proof by halves when a Bezier's whole hull lies well within
// one chord's room (Proof::surely_near_chord, geometry.cpp): it must give exactly what
// corner_bezier_within() gives, which always runs the proof. Checked on lane changes built as
// Planner::offset_corner builds them, at random and right at the edges the rounding argument
// covers: offsets just inside and outside the limit, coordinates near 1e7 times the room,
// nearly straight corners, tiny and large tolerances.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "motion/geometry.hpp"

namespace motion {
namespace {

struct Corner {
    Element before, after;
    double tol_mm, d_mm, lp_mm, ls_mm;
};

// Two lines through a corner in `dims` random axes, turning by `angle_rad`, and the sizes of
// an offset corner: offset d, parabola cut lp, shift length ls.
Corner make_corner(std::mt19937_64& rng, int dims, double angle_rad, double centre_mm,
                   double tol_mm, double d_share) {
    std::uniform_real_distribution<double> unit(-1, 1);
    std::array<int, kAxes> order{0, 1, 2, 3, 4, 5, 6, 7, 8};
    std::shuffle(order.begin(), order.end(), rng);
    // Orthonormal e1, e2 in the chosen axes; t1 = e1, t2 = cos e1 + sin e2.
    AxisArray e1{}, e2{};
    for (int j = 0; j < dims; ++j) e1[order[j]] = unit(rng), e2[order[j]] = unit(rng);
    auto normalise = [](AxisArray& v) {
        double n = 0;
        for (double x : v) n += x * x;
        for (double& x : v) x /= std::sqrt(n);
    };
    normalise(e1);
    double dot = 0;
    for (int k = 0; k < kAxes; ++k) dot += e1[k] * e2[k];
    for (int k = 0; k < kAxes; ++k) e2[k] -= dot * e1[k];
    normalise(e2);
    AxisArray t1 = e1, t2{}, c{};
    for (int k = 0; k < kAxes; ++k) {
        t2[k] = std::cos(angle_rad) * e1[k] + std::sin(angle_rad) * e2[k];
        c[k] = centre_mm * unit(rng);
    }
    Corner out{};
    out.tol_mm = tol_mm;
    out.d_mm = d_share * tol_mm;
    out.lp_mm = 8 * tol_mm * std::uniform_real_distribution<double>(0.3, 1.2)(rng);
    out.ls_mm = out.lp_mm * std::uniform_real_distribution<double>(2, 20)(rng);
    const double len_mm = 3 * (out.lp_mm + out.ls_mm);
    AxisArray start{}, end{};
    for (int k = 0; k < kAxes; ++k) {
        start[k] = c[k] - len_mm * t1[k];
        end[k] = c[k] + len_mm * t2[k];
    }
    out.before = make_line(start, c);
    out.after = make_line(c, end);
    return out;
}

bool same_points(const BezierPoints& a, const BezierPoints& b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}

// Both lane changes of the corner, as Planner::offset_corner builds and checks them.
// Returns how many were proved (0-2).
int check_corner(const Corner& k) {
    const AxisArray &t1 = k.before.a, &t2 = k.after.a, &c = k.before.end;
    double cos_t = 0;
    for (int i = 0; i < kAxes; ++i) cos_t += t1[i] * t2[i];
    const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
    const double back = k.d_mm * (1 - cos_t) / sin_t;
    const double cut_mm = k.lp_mm - back + k.ls_mm;
    AxisArray n1, n2, c2, a0, a3, b0, b3;
    for (int i = 0; i < kAxes; ++i) {
        n1[i] = -(t2[i] - cos_t * t1[i]) / sin_t;
        n2[i] = (t1[i] - cos_t * t2[i]) / sin_t;
        c2[i] = c[i] + k.d_mm * (t1[i] - t2[i]) / sin_t;
        a3[i] = c2[i] - k.lp_mm * t1[i];
        a0[i] = a3[i] - k.ls_mm * t1[i] - k.d_mm * n1[i];
        b0[i] = c2[i] + k.lp_mm * t2[i];
        b3[i] = b0[i] + k.ls_mm * t2[i] - k.d_mm * n2[i];
    }
    const CornerPath path = corner_path(k.before, cut_mm, k.after, cut_mm, k.tol_mm);
    const double limit_mm = 0.995 * k.tol_mm;
    int proved = 0;
    for (int side = 0; side < 2; ++side) {
        const AxisArray &p0 = side ? b0 : a0, &p3 = side ? b3 : a3, &t = side ? t2 : t1;
        BezierPoints quick{}, full{};
        const bool q = shift_bezier_within(p0, t, p3, t, k.ls_mm / 2, path, limit_mm, quick);
        const bool f = corner_bezier_within(p0, t, p3, t, k.ls_mm / 2, path, limit_mm, full);
        EXPECT_EQ(q, f) << "side " << side << " d/limit " << k.d_mm / limit_mm;
        if (q && f) {
            EXPECT_TRUE(same_points(quick, full));
        }
        proved += f;
    }
    return proved;
}

TEST(ShiftProof, RandomLaneChangesGiveTheProofsAnswer) {
    std::mt19937_64 rng(20261121);
    std::uniform_real_distribution<double> u01(0, 1);
    int proved = 0, total = 0;
    for (int i = 0; i < 20000; ++i) {
        const int dims = 2 + int(u01(rng) * 3);  // 2-4 axes
        const double angle = (0.5 + 90.5 * u01(rng)) * std::numbers::pi / 180;
        const double tol = std::pow(10.0, -4 + 4 * u01(rng));
        const double centre = std::pow(10.0, -1 + 5 * u01(rng));
        proved += check_corner(make_corner(rng, dims, angle, centre, tol, 0.1 + 0.89 * u01(rng)));
        total += 2;
    }
    // Offsets up to 0.99 of the tolerance fit its 0.995 (and the shortcut is taken): nearly all.
    EXPECT_GT(proved, total * 9 / 10);
}

TEST(ShiftProof, OffsetsAtTheLimitGiveTheProofsAnswer) {
    // The shortcut stops 1e-5 short of the room, the proof at the room: offsets on both sides
    // of each edge, where the two disagree first if the rounding argument is wrong.
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u01(0, 1);
    int proved = 0;
    for (int i = 0; i < 20000; ++i) {
        const double limit_share = 0.995 * (1 - 3e-5 + 4e-5 * u01(rng));
        const double tol = std::pow(10.0, -3 + 3 * u01(rng));
        proved +=
            check_corner(make_corner(rng, 2 + i % 2, (20 + 70 * u01(rng)) * std::numbers::pi / 180,
                                     100 * u01(rng), tol, limit_share));
    }
    EXPECT_GT(proved, 0);
}

TEST(ShiftProof, LargeCoordinatesGiveTheProofsAnswer) {
    // Coordinates from 1e5 to 1e12 times the room, across the shortcut's 1e7 bound (past
    // about 1e9 the rounding exceeds the shortcut's 1e-5 margin: without the bound this fails).
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int i = 0; i < 20000; ++i) {
        const double tol = std::pow(10.0, -3 + 2 * u01(rng));
        const double centre = tol * std::pow(10.0, 5 + 7 * u01(rng));
        const double share = i % 2 ? 0.99 : 0.995 * (1 - 2e-5 * u01(rng));
        check_corner(make_corner(rng, 2 + i % 2, (5 + 85 * u01(rng)) * std::numbers::pi / 180,
                                 centre, tol, share));
    }
}

TEST(ShiftProof, NearlyStraightCornersGiveTheProofsAnswer) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u01(0, 1);
    for (int i = 0; i < 5000; ++i) {
        const double angle = std::pow(10.0, -7 + 6 * u01(rng));  // 1e-7 to 0.1 rad
        check_corner(
            make_corner(rng, 2 + i % 3, angle, 500 * u01(rng), 0.01, 0.1 + 0.89 * u01(rng)));
    }
}

}  // namespace
}  // namespace motion
