// Seeded property test for cutter compensation on random closed contours.
//
// A contour is a star-shaped polygon (so it never crosses itself) whose edges
// are lines or arcs bulging outwards (convex) or inwards (concave); vertices are
// both convex and concave, so G41 and G42 each meet inside and outside corners.
// The tool radius is chosen below the contour's feature sizes (edge lengths,
// corner angles, arc radii, gaps between non-adjacent edges), so a correct
// compensator must succeed, and then:
//   - the output path is continuous;
//   - no point of it (start-up and cancel moves aside) is closer than r − 1e-6
//     to any contour segment;
//   - every piece that offsets segment i is at distance r ± 1e-6 from segment i,
//     and every segment has such a piece.
// Distances are computed here from the contour directly, not with the
// compensator's geometry code.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "interp/cutter_comp.hpp"

namespace {

using namespace interp::cutter;
constexpr double kPi = std::numbers::pi;

struct Piece {  // one contour segment, for distance checks
    bool arc = false;
    Vec2 a, b, c;
    bool ccw = false;
    double rho = 0, a0 = 0, sweep = 0;
};

double wrap(double x) {
    x = std::fmod(x, 2 * kPi);
    return x < 0 ? x + 2 * kPi : x;
}

Piece make_line(Vec2 a, Vec2 b) {
    return Piece{false, a, b, {0, 0}};
}

/// Arc from a to b with sagitta s (> 0 bulges to the right of travel).
Piece make_arc(Vec2 a, Vec2 b, double s) {
    const double chord = (b - a).norm();
    const Vec2 d = (b - a) / chord;
    const Vec2 n(-d.y(), d.x());
    const double rho = (chord * chord / 4 + s * s) / (2 * std::abs(s));
    Piece p;
    p.arc = true;
    p.a = a;
    p.b = b;
    p.c = (a + b) / 2 + n * (s > 0 ? 1.0 : -1.0) * (rho - std::abs(s));
    p.ccw = s > 0;
    p.rho = rho;
    p.a0 = std::atan2(a.y() - p.c.y(), a.x() - p.c.x());
    const double a1 = std::atan2(b.y() - p.c.y(), b.x() - p.c.x());
    p.sweep = wrap((p.ccw ? 1 : -1) * (a1 - p.a0));
    return p;
}

double distance(const Vec2& p, const Piece& s) {
    if (!s.arc) {
        const Vec2 d = s.b - s.a;
        const double t = std::clamp((p - s.a).dot(d) / d.squaredNorm(), 0.0, 1.0);
        return (p - (s.a + d * t)).norm();
    }
    const double ang =
        wrap((s.ccw ? 1 : -1) * (std::atan2(p.y() - s.c.y(), p.x() - s.c.x()) - s.a0));
    if (ang <= s.sweep) return std::abs((p - s.c).norm() - s.rho);
    return std::min((p - s.a).norm(), (p - s.b).norm());
}

Vec2 sample(const Piece& s, double t) {
    if (!s.arc) return s.a + (s.b - s.a) * t;
    const double ang = s.a0 + (s.ccw ? 1 : -1) * s.sweep * t;
    return s.c + s.rho * Vec2(std::cos(ang), std::sin(ang));
}

Vec2 tangent(const Piece& s, double t) {
    if (!s.arc) return (s.b - s.a).normalized();
    const Vec2 r = (sample(s, t) - s.c).normalized();
    return s.ccw ? Vec2(-r.y(), r.x()) : Vec2(r.y(), -r.x());
}

Vec2 sample(const OutMove& m, double t) {
    if (m.shape == Shape::Line) return m.start + (m.end - m.start) * t;
    const Vec2 r0 = m.start - m.centre;
    const double ang = std::atan2(r0.y(), r0.x()) + (m.ccw ? 1 : -1) * m.sweep_rad * t;
    return m.centre + r0.norm() * Vec2(std::cos(ang), std::sin(ang));
}

struct Contour {
    std::vector<Piece> pieces;  // closed, starting and ending at the middle of edge 0
    double max_radius = 0;      // the feature-size bound for the tool
};

Contour random_contour(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = 5 + static_cast<int>(6 * u(rng));
    std::vector<Vec2> v;
    for (int i = 0; i < n; ++i) {
        const double ang = 2 * kPi * (i + 0.6 * (u(rng) - 0.5)) / n;
        const double rad = 20 + 30 * u(rng);
        v.emplace_back(rad * std::cos(ang), rad * std::sin(ang));
    }
    if (u(rng) < 0.5) std::reverse(v.begin(), v.end());  // CW contours too

    Contour c;
    const Vec2 mid = (v[0] + v[1]) / 2;
    c.pieces.push_back(make_line(mid, v[1]));
    for (int i = 1; i < n; ++i) {
        const Vec2 a = v[i], b = v[(i + 1) % n];
        if (u(rng) < 0.5) {
            const double s = (b - a).norm() * (0.05 + 0.2 * u(rng)) * (u(rng) < 0.5 ? 1 : -1);
            c.pieces.push_back(make_arc(a, b, s));
        } else {
            c.pieces.push_back(make_line(a, b));
        }
    }
    c.pieces.push_back(make_line(v[0], mid));

    // Feature sizes bound the radius a correct compensator must handle.
    double bound = 1e9;
    const std::size_t m = c.pieces.size();
    for (std::size_t i = 0; i < m; ++i) {
        const Piece& p = c.pieces[i];
        bound = std::min(bound, 0.3 * (p.b - p.a).norm());
        if (p.arc) bound = std::min(bound, 0.5 * p.rho);
        const Vec2 t_in = tangent(p, 1), t_out = tangent(c.pieces[(i + 1) % m], 0);
        const double turn =
            std::atan2(std::abs(t_in.x() * t_out.y() - t_in.y() * t_out.x()), t_in.dot(t_out));
        if (turn > 150 * kPi / 180) return Contour{};  // a cusp: no tool fits, draw again
        const double half_interior = (kPi - turn) / 2;
        bound = std::min(bound, 0.3 * (p.b - p.a).norm() * std::tan(half_interior));
        for (std::size_t j = i + 2; j < m; ++j) {
            if (i == 0 && j == m - 1) continue;  // adjacent across the start
            for (int a = 0; a <= 30; ++a)
                bound = std::min(bound, 0.45 * distance(sample(p, a / 30.0), c.pieces[j]));
        }
    }
    c.max_radius = bound;
    return c;
}

/// With helix set, move i ends 0.5 mm lower than move i−1 (a descending
/// spiral): the heights must run continuously (no vertical step at a trimmed
/// corner) and each offset piece must end within its move's height range.
/// `may_skip[i]`: segment i is shorter than the tool can follow (a chamfer inserted at an inside
/// corner); it may have no piece of its own, but the path must still keep r from it.
void check_contour(const Contour& c, Side side, double r, std::uint32_t seed, bool helix = false,
                   const std::vector<bool>& may_skip = {}) {
    auto end_h = [&](SourceTag tag) { return helix ? -0.5 * static_cast<double>(tag) : 0.0; };
    const std::size_t m = c.pieces.size();
    const Vec2 d0 = (c.pieces[0].b - c.pieces[0].a).normalized();
    const double s = side == Side::Left ? 1 : -1;
    const Vec2 start = c.pieces[0].a + Vec2(-d0.y(), d0.x()) * (s * 5 * r);

    Compensator comp(Config{}, start);
    auto push = [&](const Piece& p, Side sd, SourceTag tag) {
        Move mv;
        mv.shape = p.arc ? Shape::Arc : Shape::Line;
        mv.end = p.b;
        mv.centre = p.c;
        mv.ccw = p.ccw;
        mv.side = sd;
        mv.radius_mm = r;
        mv.tag = tag;
        mv.end_h = end_h(tag);
        comp.push(mv);
    };
    push(make_line(start, c.pieces[0].a), side, 1);
    for (std::size_t i = 0; i < m; ++i) push(c.pieces[i], side, static_cast<SourceTag>(i + 2));
    push(make_line(c.pieces[0].a, start), Side::Off, static_cast<SourceTag>(m + 2));
    double at_h = 0.0;
    comp.finish();
    std::vector<bool> covered(m, false);
    Vec2 at = start;
    for (const Output& o : comp.drain()) {
        const auto* mv = std::get_if<OutMove>(&o);
        ASSERT_NE(mv, nullptr) << "seed " << seed;
        ASSERT_LT((mv->start - at).norm(), 1e-7)
            << "seed " << seed << " gap before tag " << mv->tag;
        ASSERT_NEAR(mv->start_h, at_h, 1e-9) << "seed " << seed << " tag " << mv->tag;
        at = mv->end;
        at_h = mv->end_h;
        if (mv->role == Role::Contour) {
            const double lo = std::min(end_h(mv->tag - 1), end_h(mv->tag)) - 1e-9;
            const double hi = std::max(end_h(mv->tag - 1), end_h(mv->tag)) + 1e-9;
            EXPECT_TRUE(mv->end_h >= lo && mv->end_h <= hi)
                << "seed " << seed << " tag " << mv->tag;
        }
        if (mv->role == Role::Startup || mv->role == Role::Cancel) continue;
        for (int k = 0; k <= 40; ++k) {
            const Vec2 p = sample(*mv, k / 40.0);
            for (std::size_t j = 0; j < m; ++j) {
                ASSERT_GE(distance(p, c.pieces[j]), r - 1e-6)
                    << "seed " << seed << " tag " << mv->tag << " near segment " << j + 2;
            }
            if (mv->role == Role::Contour) {
                ASSERT_NEAR(distance(p, c.pieces[mv->tag - 2]), r, 1e-6)
                    << "seed " << seed << " tag " << mv->tag;
            }
        }
        if (mv->role == Role::Contour) covered[mv->tag - 2] = true;
    }
    EXPECT_LT((at - start).norm(), 1e-9) << "seed " << seed;
    EXPECT_NEAR(at_h, end_h(static_cast<SourceTag>(m + 2)), 1e-9) << "seed " << seed;
    for (std::size_t i = 0; i < m; ++i)
        EXPECT_TRUE(covered[i] || (i < may_skip.size() && may_skip[i]))
            << "seed " << seed << " seg " << i;
}

/// Cuts every inside corner (for `side`) between two lines with a chamfer of length about
/// 0.1·r: far below what the tool can follow, as CAM output has at corners.
Contour with_tiny_chamfers(const Contour& c, Side side, double r, std::vector<bool>& may_skip) {
    const double s = side == Side::Left ? 1 : -1;
    Contour out;
    out.max_radius = c.max_radius;
    const std::size_t m = c.pieces.size();
    out.pieces.push_back(c.pieces[0]);
    may_skip.assign(1, false);
    for (std::size_t i = 1; i < m; ++i) {
        Piece& prev = out.pieces.back();
        Piece next = c.pieces[i];
        const Vec2 t_in = tangent(prev, 1), t_out = tangent(next, 0);
        const double turn_sin = t_in.x() * t_out.y() - t_in.y() * t_out.x();
        if (!prev.arc && !next.arc && s * turn_sin > 0.05) {
            const double d = 0.05 * r;
            const Vec2 a = prev.b - t_in * d, b = next.a + t_out * d;
            prev = make_line(prev.a, a);
            next = make_line(b, next.b);
            out.pieces.push_back(make_line(a, b));
            may_skip.push_back(true);
        }
        out.pieces.push_back(next);
        may_skip.push_back(false);
    }
    return out;
}

TEST(CutterCompProperty, TinyChamfersAtInsideCornersAreSkippedWithoutGouging) {
    int chamfers = 0;
    for (std::uint32_t seed = 1; seed <= 200; ++seed) {
        std::mt19937 rng(seed);
        Contour c;
        while (c.pieces.empty()) c = random_contour(rng);
        std::uniform_real_distribution<double> u(0.3, 1.0);
        for (const Side side : {Side::Left, Side::Right}) {
            const double r = c.max_radius * u(rng);
            std::vector<bool> may_skip;
            const Contour chamfered = with_tiny_chamfers(c, side, r, may_skip);
            for (const bool k : may_skip) chamfers += k;
            try {
                ASSERT_NO_FATAL_FAILURE(check_contour(chamfered, side, r, seed, false, may_skip));
            } catch (const CompError& e) {
                FAIL() << "seed " << seed << " side " << (side == Side::Left ? "G41" : "G42")
                       << " r " << r << ": " << e.what();
            }
        }
    }
    EXPECT_GT(chamfers, 200);  // inside corners between lines really were chamfered
}

TEST(CutterCompProperty, RandomClosedContoursKeepExactlyTheRadius) {
    int arcs = 0, runs = 0;
    for (std::uint32_t seed = 1; seed <= 300; ++seed) {
        std::mt19937 rng(seed);
        Contour c;
        while (c.pieces.empty()) c = random_contour(rng);
        std::uniform_real_distribution<double> u(0.3, 1.0);
        for (const Side side : {Side::Left, Side::Right}) {
            const double r = c.max_radius * u(rng);
            try {
                ASSERT_NO_FATAL_FAILURE(check_contour(c, side, r, seed));
                ASSERT_NO_FATAL_FAILURE(check_contour(c, side, r, seed, true));
            } catch (const CompError& e) {
                FAIL() << "seed " << seed << " side " << (side == Side::Left ? "G41" : "G42")
                       << " r " << r << ": " << e.what();
            }
            ++runs;
        }
        for (const auto& p : c.pieces) arcs += p.arc;
    }
    EXPECT_EQ(runs, 600);
    EXPECT_GT(arcs, 300);  // the contours really mix lines and arcs
}

}  // namespace

namespace {

// Random, mostly invalid programs: the compensator either accepts them with a
// continuous, finite output path or rejects them with a CompError; nothing else.
TEST(CutterCompProperty, ArbitraryInputFailsCleanlyOrStaysContinuous) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int rejected = 0, accepted = 0;
    for (int program = 0; program < 2000; ++program) {
        Config cfg;
        cfg.lookahead_moves = static_cast<std::size_t>(4 * u(rng));
        cfg.on_exhausted =
            u(rng) < 0.5 ? OnLookaheadExhausted::Error : OnLookaheadExhausted::Perpendicular;
        cfg.extend_max_turn_deg = 120 * u(rng);
        cfg.cancel_at_inside_corner =
            u(rng) < 0.5 ? CancelCorner::Perpendicular : CancelCorner::Intersection;
        Compensator comp(cfg);
        Vec2 at(0, 0);
        std::vector<Output> out;
        try {
            for (int i = 0; i < 12; ++i) {
                if (u(rng) < 0.1) {
                    comp.push(Marker{i});
                    continue;
                }
                Move m;
                m.tag = i;
                m.end = u(rng) < 0.15 ? at : Vec2(20 * u(rng) - 10, 20 * u(rng) - 10);
                m.end_h = u(rng) < 0.2 ? -5 * u(rng) : 0.0;
                if (u(rng) < 0.3) {
                    m.shape = Shape::Arc;
                    m.ccw = u(rng) < 0.5;
                    // The centre on the bisector keeps the radius consistent, as the
                    // executor's arc check guarantees.
                    const Vec2 mid = (at + m.end) / 2, d = m.end - at;
                    m.centre = mid + Vec2(-d.y(), d.x()) * (2 * u(rng) - 1);
                }
                const double side = u(rng);
                m.side = side < 0.3 ? Side::Off : side < 0.65 ? Side::Left : Side::Right;
                m.radius_mm = 3 * u(rng) - 0.5;
                m.plane = u(rng) < 0.03 ? 18 : 17;
                comp.push(m);
                at = m.end;
                for (auto& o : comp.drain()) out.push_back(o);
            }
            comp.finish();
            for (auto& o : comp.drain()) out.push_back(o);
            ++accepted;
        } catch (const CompError&) {
            ++rejected;
            continue;
        }
        Vec2 tool(0, 0);
        for (const Output& o : out) {
            const auto* m = std::get_if<OutMove>(&o);
            if (!m) continue;
            ASSERT_TRUE(std::isfinite(m->end.x()) && std::isfinite(m->end.y())) << program;
            ASSERT_LT((m->start - tool).norm(), 1e-6) << "program " << program << " tag " << m->tag;
            tool = m->end;
        }
    }
    EXPECT_GT(accepted, 100);
    EXPECT_GT(rejected, 100);
}

}  // namespace
