// G34–G37 hole positions. The manual gives the words and the K sign rule but no
// formulas; the angle step of G34 is 360°/|K| and clockwise means decreasing
// angle (REC SC-6), G37 is serpentine (REC SC-9).

#include "interp/hole_patterns.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace interp::cycles {
namespace {

constexpr long kMaxHoles = 9999;

Vec2 polar(Vec2 centre, double radius, double angle_deg) {
    const double a = angle_deg * std::numbers::pi / 180.0;
    return {centre[0] + radius * std::cos(a), centre[1] + radius * std::sin(a)};
}

void check_signed_count(int g, long count) {
    if (count == 0) throw CycleError(fmt::format("G{}: the hole count K must not be 0", g));
    if (count < -kMaxHoles || count > kMaxHoles)
        throw CycleError(fmt::format("G{}: the hole count K={} is outside -9999…9999", g, count));
}

void check_positive_count(int g, char letter, long count) {
    if (count <= 0 || count > kMaxHoles)
        throw CycleError(
            fmt::format("G{}: the hole count {}={} must be between 1 and 9999", g, letter, count));
}

HolePattern arc_pattern(Vec2 centre, double radius, double first_deg, double step_deg,
                        long count) {
    // K > 0 runs clockwise: the angle decreases.
    const double signed_step = (count > 0 ? -1.0 : 1.0) * step_deg;
    return {std::labs(count), [=](long i) {
                return polar(centre, radius, first_deg + signed_step * static_cast<double>(i));
            }};
}

HolePattern line_pattern(Vec2 start, double spacing, double angle_deg, long count) {
    check_positive_count(35, 'K', count);
    return {count,
            [=](long i) { return polar(start, spacing * static_cast<double>(i), angle_deg); }};
}

HolePattern grid_pattern(Vec2 start, double pitch_x, long count_x, double pitch_y,
                         long count_y) {
    check_positive_count(37, 'P', count_x);
    check_positive_count(37, 'K', count_y);
    // Serpentine rows (REC SC-9): even rows run +X, odd rows come back.
    return {count_x * count_y, [=](long i) -> Vec2 {
                const long row = i / count_x;
                const long n = i % count_x;
                const long col = row % 2 == 0 ? n : count_x - 1 - n;
                return {start[0] + pitch_x * static_cast<double>(col),
                        start[1] + pitch_y * static_cast<double>(row)};
            }};
}

std::vector<Vec2> list(const HolePattern& p) {
    std::vector<Vec2> holes;
    holes.reserve(static_cast<std::size_t>(p.count));
    for (long i = 0; i < p.count; ++i) holes.push_back(p.at(i));
    return holes;
}

template <typename T>
T require(const std::optional<T>& word, int g, char letter) {
    if (!word) throw CycleError(fmt::format("G{}: the word {} is missing", g, letter));
    return *word;
}

long whole_count(double value, int g, char letter) {
    if (value != std::floor(value))
        throw CycleError(fmt::format("G{}: {} must be a whole number, got {:g}", g, letter, value));
    // Far beyond every count range below; keeps the conversion to long defined.
    if (std::abs(value) > 1e9)
        throw CycleError(fmt::format("G{}: the hole count {}={:g} is out of range", g, letter, value));
    return static_cast<long>(value);
}

}  // namespace

std::vector<Vec2> g34_bolt_circle(Vec2 centre, double radius, double first_deg, long count) {
    check_signed_count(34, count);
    return list(arc_pattern(centre, radius, first_deg,
                            360.0 / static_cast<double>(std::labs(count)), count));
}

std::vector<Vec2> g35_line(Vec2 start, double spacing, double angle_deg, long count) {
    return list(line_pattern(start, spacing, angle_deg, count));
}

std::vector<Vec2> g36_arc(Vec2 centre, double radius, double first_deg, double step_deg,
                          long count) {
    check_signed_count(36, count);
    return list(arc_pattern(centre, radius, first_deg, step_deg, count));
}

std::vector<Vec2> g37_grid(Vec2 start, double pitch_x, long count_x, double pitch_y, long count_y) {
    return list(grid_pattern(start, pitch_x, count_x, pitch_y, count_y));
}

HolePattern hole_pattern_lazy(int g, const PatternWords& w, bool incremental, Vec2 current,
                              bool cycle_active) {
    if (!cycle_active)
        throw CycleError(
            "G34/35/36/37 instruction error: special canned cycle mismatch, none specified");
    const Vec2 origin =
        incremental ? Vec2{current[0] + w.x_mm.value_or(0.0), current[1] + w.y_mm.value_or(0.0)}
                    : Vec2{w.x_mm.value_or(current[0]), w.y_mm.value_or(current[1])};
    switch (g) {
        case 34: {
            const long k = whole_count(require(w.k, g, 'K'), g, 'K');
            check_signed_count(34, k);
            return arc_pattern(origin, require(w.i, g, 'I'), w.j.value_or(0.0),
                               360.0 / static_cast<double>(std::labs(k)), k);
        }
        case 35:
            return line_pattern(origin, require(w.i, g, 'I'), w.j.value_or(0.0),
                                whole_count(require(w.k, g, 'K'), g, 'K'));
        case 36: {
            const long k = whole_count(require(w.k, g, 'K'), g, 'K');
            check_signed_count(36, k);
            return arc_pattern(origin, require(w.i, g, 'I'), w.j.value_or(0.0),
                               require(w.p, g, 'P'), k);
        }
        case 37:
            return grid_pattern(origin, require(w.i, g, 'I'),
                                whole_count(require(w.p, g, 'P'), g, 'P'), require(w.j, g, 'J'),
                                whole_count(require(w.k, g, 'K'), g, 'K'));
    }
    throw CycleError(fmt::format("G{} is not a hole-pattern cycle (G34…G37)", g));
}

std::vector<Vec2> hole_pattern(int g, const PatternWords& w, bool incremental, Vec2 current,
                               bool cycle_active) {
    return list(hole_pattern_lazy(g, w, incremental, current, cycle_active));
}

}  // namespace interp::cycles
