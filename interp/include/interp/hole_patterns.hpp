#pragma once
// NcStudio hole-pattern cycles G34–G37 (S0 §3.7, FEATURES SC-1…SC-11): pure
// functions from the pattern words to hole positions in X/Y. The holes are then
// drilled with the active canned cycle (CycleState::drill_at), which moves
// between them at rapid. Lengths mm, angles degrees counter-clockwise from +X.
//
// Throws cycles::CycleError (message without location) on bad words.

#include <array>
#include <optional>
#include <vector>

#include "interp/cycles.hpp"

namespace interp::cycles {

using Vec2 = std::array<double, 2>;

/// G34 bolt circle: count holes equally spaced on the full circle starting at
/// first_angle_deg; count > 0 runs clockwise, < 0 counter-clockwise, |count| ≤ 9999.
std::vector<Vec2> g34_bolt_circle(Vec2 centre_mm, double radius_mm, double first_angle_deg,
                                  long count);
/// G35 holes on a line at angle_deg from start; negative spacing drills the
/// other way; 1 ≤ count ≤ 9999.
std::vector<Vec2> g35_line(Vec2 start_mm, double spacing_mm, double angle_deg, long count);
/// G36 holes on an arc, step_deg apart; count sign and range as G34.
std::vector<Vec2> g36_arc(Vec2 centre_mm, double radius_mm, double first_angle_deg, double step_deg,
                          long count);
/// G37 grid: count_x holes pitch_x apart along X, count_y rows pitch_y apart in Y,
/// visited row by row, serpentine, the first row at start.
std::vector<Vec2> g37_grid(Vec2 start_mm, double pitch_x_mm, long count_x, double pitch_y_mm,
                           long count_y);

/// The words of a G34–G37 block (P is the G36 angle step or the G37 X count).
struct PatternWords {
    std::optional<double> x_mm, y_mm, i, j, p;
    std::optional<double> k;  // as written; must be a whole number
};

/// A pattern's holes by index, computed on demand (a G37 grid may hold 9999×9999 holes).
struct HolePattern {
    long count = 0;
    HoleAt at;  // hole i (0 ≤ i < count) in X/Y
};

/// Dispatches a G34…G37 block: checks that a canned cycle is active (the
/// manual's error text otherwise), resolves X/Y under G90/G91 (incremental from
/// current_xy) and validates the words; the holes are produced on demand.
HolePattern hole_pattern_lazy(int g_number, const PatternWords& words, bool incremental,
                              Vec2 current_xy_mm, bool cycle_active);
/// hole_pattern_lazy with every position listed.
std::vector<Vec2> hole_pattern(int g_number, const PatternWords& words, bool incremental,
                               Vec2 current_xy_mm, bool cycle_active);

}  // namespace interp::cycles
