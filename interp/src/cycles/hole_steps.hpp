#pragma once
// Internal seam between the cycle data rules (cycle_state.cpp) and the per-cycle
// step generators (hole_steps.cpp).

#include "interp/cycles.hpp"

namespace interp::cycles::detail {

AxisMap axis_map(Plane plane, bool drill_axis_follows_plane);

/// Throws CycleError when the block's levels, peck depth or spindle direction make every hole
/// impossible; called once, before any hole is generated.
void check_hole(const HoleSpec& hole, const BlockContext& ctx, const CycleConfig& cfg);

/// Appends the steps of one hole to steps, starting from position (updated to the tool position
/// after the hole). check_hole must have accepted the spec.
void append_hole(const HoleSpec& hole, const BlockContext& ctx, const CycleConfig& cfg,
                 Vec3& position, std::vector<Step>& steps);

/// Unit shift vector in (a, b) for the oriented-stop direction parameter.
std::array<double, 2> oss_shift(const CycleConfig& cfg);

}  // namespace interp::cycles::detail
