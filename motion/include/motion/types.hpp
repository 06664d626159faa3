// Plain value types shared by the planner, the sampler and the kinematics.
// Units: lengths in mm (rotary axes in degrees, treated like mm by the planner), time in s.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace motion {

inline constexpr int kAxes = 9;  // X Y Z A B C U V W, in this order
using AxisArray = std::array<double, kAxes>;

// Limits of the joints (motors) of a linear kinematics, q = M p with M constant (trivial,
// gantry, CoreXY), in joint units: the planner and the sampler keep joint j's velocity
// |sum_k rows[j][k] p'_k ds/dt| and its acceleration and jerk within them as they keep each
// axis within its own. Only the joints whose limits the axis limits do not already imply are
// listed (set_linear_joints(), limits.hpp), so a machine whose motors are as fast as its axes
// has count 0 and plans exactly as without joints. Velocity and acceleration are > 0 and
// finite; a jerk of 0 means unlimited.
struct JointLimits {
    int count = 0;
    std::array<AxisArray, kAxes> rows{};  // joint j = sum over k of rows[j][k] * axis k
    AxisArray vel_mm_s{};
    AxisArray acc_mm_s2{};
    AxisArray jerk_mm_s3{};
};

// Per-axis machine limits. A jerk of 0 means "unlimited" for that axis (trapezoidal profiles).
struct AxisLimits {
    AxisArray vel_mm_s{};
    AxisArray acc_mm_s2{};
    AxisArray jerk_mm_s3{};
    JointLimits joints{};  // none by default: the axes' limits are the machine's
};

enum class SegmentKind : std::uint8_t { Line, Arc };

// One programmed move in machine coordinates, as the interpreter emits it. The move starts where
// the previous one ended (the planner's start position for the first one).
struct PathSegment {
    SegmentKind kind = SegmentKind::Line;
    AxisArray end_mm{};
    // Arcs only: the circle lies in the plane of axes (plane_first, plane_second), which is
    // right-handed about plane_normal; centre_mm holds the centre's coordinates in that plane.
    // turns > 0 is counter-clockwise seen from +normal (G03), turns < 0 clockwise (G02);
    // |turns| - 1 extra full revolutions, and end == start in the plane is a full circle.
    int plane_first = 0;
    int plane_second = 1;
    int plane_normal = 2;
    std::array<double, 2> centre_mm{};
    int turns = 1;

    double feed_mm_s = 0;  // requested path speed; ignored for rapids
    bool rapid = false;    // G0: as fast as the axis limits allow
    // Rapids only: the programmed rapid rate (NcStudio's F in a G00 block), a cap on the path
    // speed below the axis limits; 0 = no cap.
    double rapid_mm_s = 0;
    bool exact_stop = false;  // G09 (or G61 handled by tolerance 0): stop at this move's end
    // Blend tolerance for the corner at this move's end (G64 P). 0 = exact path (G61): corners
    // that are not tangent are stopped at, never rounded.
    double tolerance_mm = 0;
    std::int32_t line = 0;      // source line tag, reported back while the move runs
    std::uint32_t move_id = 0;  // opaque tag copied to the records made from this segment
};

// A segment the planner cannot follow: names the source line and what is wrong.
class PlanError : public std::runtime_error {
  public:
    PlanError(std::int32_t line, const std::string& what)
        : std::runtime_error("line " + std::to_string(line) + ": " + what), line_(line) {}
    std::int32_t line() const noexcept { return line_; }

  private:
    std::int32_t line_;
};

}  // namespace motion
