#pragma once
// Internal seam between the cycle data rules (cycle_state.cpp) and the per-cycle
// step generators (hole_steps.cpp).

#include "interp/cycles.hpp"

namespace interp::cycles::detail {

/// Indices into Vec3 of the two positioning axes (a, b) and the drilling axis c.
struct AxisMap {
    int a;
    int b;
    int c;
};
AxisMap axis_map(Plane plane, bool drill_axis_follows_plane);

/// Everything one hole needs, resolved to absolute levels on the drilling axis.
struct HoleSpec {
    CycleCode code;
    AxisMap axes;
    double pos_a_mm;
    double pos_b_mm;
    double r_mm;
    double z_mm;
    double initial_mm;
    bool return_to_r;
    double q_mm;
    double dwell_s;
    double feed_mm_min;
    double spindle_rpm;
    std::array<double, 2> shift_dir;  // unit vector in (a, b) for G76/G87
};

/// Appends the steps of one hole to out, starting from position (updated to the
/// tool position after the hole). Throws CycleError for impossible geometry.
void append_hole(const HoleSpec& hole, const BlockContext& ctx, const CycleConfig& cfg,
                 Vec3& position, Expansion& out);

/// Unit shift vector in (a, b) for the oriented-stop direction parameter.
std::array<double, 2> oss_shift(const CycleConfig& cfg);

}  // namespace interp::cycles::detail
