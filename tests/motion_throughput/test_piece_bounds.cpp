// bounds(e, moving) computes a corner piece's bounds in the axes its path moves only (the
// planner passes them for the pieces it builds with make_corner_bezier() on a path at rest,
// Planner::Junction::set_piece_axes): it must give exactly what bounds(e) gives, every member
// bit for bit. Checked on the pieces of corners between lines and between an arc and a line
// in 2-4 of the 9 axes, at random positions (still axes at +0, -0 or elsewhere), on Beziers
// too short for finite factors, and on the other element kinds (which bounds(e) handles).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <new>
#include <numbers>
#include <random>
#include <span>

#include "motion/geometry.hpp"

namespace motion {
namespace {

// The result of make() built in bytes filled with 0xab first: a member it leaves unwritten
// keeps that pattern and shows in the comparison.
template <class Make>
ElementBounds built_in_dirty_bytes(Make&& make) {
    alignas(ElementBounds) unsigned char bytes[sizeof(ElementBounds)];
    std::memset(bytes, 0xab, sizeof bytes);
    ElementBounds* b = ::new (bytes) ElementBounds(make());
    return *b;
}

bool same_bits(const AxisArray& x, const AxisArray& y) {
    return std::memcmp(x.data(), y.data(), sizeof(AxisArray)) == 0;
}

// Compares bounds(e, moving) with bounds(e); returns whether e moves in any axis.
bool expect_same_bounds(const Element& e, std::span<const int> moving, const char* what) {
    const ElementBounds got = built_in_dirty_bytes([&] { return bounds(e, moving); });
    const ElementBounds want = built_in_dirty_bytes([&] { return bounds(e); });
    EXPECT_TRUE(same_bits(got.g1, want.g1)) << what;
    EXPECT_TRUE(same_bits(got.g2, want.g2)) << what;
    EXPECT_TRUE(same_bits(got.g3, want.g3)) << what;
    EXPECT_TRUE(same_bits(got.tangential_in_plane, want.tangential_in_plane)) << what;
    EXPECT_TRUE(same_bits(got.linear, want.linear)) << what;
    EXPECT_EQ(got.axis_count, want.axis_count) << what;
    for (int i = 0; i < want.axis_count && i < kAxes; ++i)
        EXPECT_EQ(got.axes[i], want.axes[i]) << what << ", listed axis " << i;
    return want.axis_count > 0;
}

std::span<const int> moving_axes(const CornerPath& path) {
    return {path.axes.data(), static_cast<std::size_t>(path.dims)};
}

// A point with its still axes (those not in `axes`) at +0, -0 or a random value.
AxisArray random_point(std::mt19937_64& rng, double scale_mm) {
    std::uniform_real_distribution<double> unit(-1, 1);
    AxisArray p;
    for (int k = 0; k < kAxes; ++k) {
        const int pick = int(rng() % 3);
        p[k] = pick == 0 ? 0.0 : pick == 1 ? -0.0 : scale_mm * unit(rng);
    }
    return p;
}

// Unit vector in the listed axes.
AxisArray random_direction(std::mt19937_64& rng, const std::array<int, kAxes>& order, int dims) {
    std::uniform_real_distribution<double> unit(-1, 1);
    AxisArray t{};
    double n = 0;
    for (int j = 0; j < dims; ++j) t[order[j]] = unit(rng), n += t[order[j]] * t[order[j]];
    for (double& x : t) x /= std::sqrt(n);
    return t;
}

TEST(PieceBounds, LineCornerPiecesGiveTheFullBounds) {
    // The offset corner's two lane changes and the Bezier blend between two lines, as the
    // planner builds and proves them, in 2-4 random axes.
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u01(0, 1);
    int compared = 0;
    for (int i = 0; i < 20000; ++i) {
        std::array<int, kAxes> order{0, 1, 2, 3, 4, 5, 6, 7, 8};
        std::shuffle(order.begin(), order.end(), rng);
        const int dims = 2 + i % 3;
        const double scale = std::pow(10.0, -1 + 4 * u01(rng));
        const AxisArray c = random_point(rng, scale);
        const AxisArray t1 = random_direction(rng, order, dims);
        const AxisArray t2 = random_direction(rng, order, dims);
        const double tol = std::pow(10.0, -3 + 3 * u01(rng)), len = 50 * tol * (1 + u01(rng));
        AxisArray start, end;
        for (int k = 0; k < kAxes; ++k) start[k] = c[k] - len * t1[k], end[k] = c[k] + len * t2[k];
        const Element before = make_line(start, c), after = make_line(c, end);
        const CornerPath path = corner_path(before, len, after, len, tol);
        ASSERT_TRUE(path.still_at_rest);
        const double l = tol * (0.5 + 3 * u01(rng));
        CurvePoint a, b;
        evaluate_upto(before, before.length_mm - l, 1, a);
        evaluate_upto(after, l, 1, b);
        BezierPoints blend, shift;
        Element piece;
        if (corner_bezier_within(a.p, a.d1, b.p, b.d1, l, path, tol, blend)) {
            make_corner_bezier(blend, path, piece);
            compared += expect_same_bounds(piece, moving_axes(path), "line corner blend");
        }
        // A lane change off the first line by d outwards, as offset_corner's shift_out.
        AxisArray p3 = a.p;
        const double d = tol * 0.9 * u01(rng);
        for (int k = 0; k < kAxes; ++k) p3[k] += d * (t1[k] - t2[k]);
        if (shift_bezier_within(start, t1, p3, t1, l, path, tol, shift)) {
            make_corner_bezier(shift, path, piece);
            compared += expect_same_bounds(piece, moving_axes(path), "lane change");
        }
    }
    EXPECT_GT(compared, 10000);
}

TEST(PieceBounds, ArcCornerPiecesGiveTheFullBounds) {
    // An arc in a random plane of the 9 axes into a line: the blend the planner builds with
    // corner_bezier_within on points and tangents of the two moves.
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u01(0, 1);
    int compared = 0;
    for (int i = 0; i < 5000; ++i) {
        std::array<int, kAxes> order{0, 1, 2, 3, 4, 5, 6, 7, 8};
        std::shuffle(order.begin(), order.end(), rng);
        PathSegment seg;
        seg.kind = SegmentKind::Arc;
        seg.plane_first = order[0], seg.plane_second = order[1], seg.plane_normal = order[2];
        seg.turns = u01(rng) < 0.5 ? 1 : -1;
        const double r = 1 + 20 * u01(rng);
        AxisArray start = random_point(rng, 50);
        seg.centre_mm = {start[order[0]] - r, start[order[1]]};
        seg.end_mm = start;
        const double phi = (10 + 150 * u01(rng)) * std::numbers::pi / 180;
        seg.end_mm[order[0]] = seg.centre_mm[0] + r * std::cos(phi);
        seg.end_mm[order[1]] = seg.centre_mm[1] + seg.turns * r * std::sin(phi);
        if (i % 2) seg.end_mm[order[2]] += 2 * u01(rng);  // a helix
        const Element arc = make_arc(start, seg);
        const AxisArray t2 = random_direction(rng, order, 3);
        AxisArray end;
        for (int k = 0; k < kAxes; ++k) end[k] = arc.end[k] + 10 * t2[k];
        const Element line = make_line(arc.end, end);
        const double tol = 0.01 + 0.1 * u01(rng), l = 0.2 * arc.length_mm * u01(rng) + 1e-3;
        const CornerPath path = corner_path(arc, 2 * l, line, 2 * l, tol);
        if (!path.still_at_rest) continue;
        CurvePoint a, b;
        evaluate_upto(arc, arc.length_mm - l, 1, a);
        evaluate_upto(line, l, 1, b);
        BezierPoints blend;
        Element piece;
        for (double share : {1.0, 0.5, 0.25}) {
            if (!corner_bezier_within(a.p, a.d1, b.p, b.d1, l * share, path, tol, blend)) continue;
            make_corner_bezier(blend, path, piece);
            compared += expect_same_bounds(piece, moving_axes(path), "arc corner blend");
            break;
        }
    }
    EXPECT_GT(compared, 100);
}

TEST(PieceBounds, BeziersWithoutFiniteFactorsAndOtherElementsAreTheFullBounds) {
    const std::array<int, 2> xy{0, 1};
    AxisArray p0{}, p1{}, p2{}, p3{};
    p0[2] = p1[2] = p2[2] = p3[2] = 5;  // a still axis away from 0
    // 1 / length overflows its square and cube (length 1e-160 mm), then all of it (a point).
    p1[0] = 1e-160, p2[0] = 2e-160, p3[0] = 3e-160, p3[1] = 1e-160;
    expect_same_bounds(make_bezier(p0, p1, p2, p3), xy, "factors not finite");
    expect_same_bounds(make_bezier(p0, p0, p0, p0), xy, "a point");
    p1[0] = 1, p2[0] = 2, p2[1] = 1, p3[0] = 3, p3[1] = 3;
    EXPECT_TRUE(expect_same_bounds(make_bezier(p0, p1, p2, p3), xy, "a plain Bezier"));
    AxisArray end = p3;
    end[4] = -2;  // moves an axis the list leaves out: lines are not computed from the list
    EXPECT_TRUE(expect_same_bounds(make_line(p0, end), xy, "line"));
    EXPECT_TRUE(expect_same_bounds(make_blend(p3, make_line(p0, p3).a, make_line(p3, end).a, 0.5),
                                   xy, "quartic blend"));
}

}  // namespace
}  // namespace motion
