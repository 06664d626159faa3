#pragma once
// Arc geometry in the working plane (FEATURES ARC-3, ARC-4, ARC-10, ARC-11): centre from R or
// I/J/K, end-point tolerance check, sweep. Coordinates are (first, second) of the plane in mm;
// positive angles are counter-clockwise (G03).
#include <Eigen/Core>
#include <optional>
#include <string>

namespace interp {

struct ArcInput {
    Eigen::Vector2d start{0, 0};
    Eigen::Vector2d end{0, 0};
    bool ccw = false;
    std::optional<double> radius;           // R word (negative = more than 180°)
    std::optional<Eigen::Vector2d> centre;  // from I/J/K, absolute
    double tolerance_mm = 0.01;
    bool v54_small_radius_is_half_circle = false;  // ARC-10
    // false: sweep_rad is left 0. The back end needs the sweep only for a V5.4 K-lead helix
    // (ARC-9), and it costs an atan2, a tenth of an arc block's time.
    bool want_sweep = true;
};

struct ArcResult {
    Eigen::Vector2d centre{0, 0};
    double radius_mm = 0;
    double sweep_rad = 0;  // always positive, in the direction of travel; 2π for a full circle
                           // (0 when not wanted, see ArcInput::want_sweep)
};

// Empty string on success, else the error text.
std::string solve_arc(const ArcInput& in, ArcResult& out);

}  // namespace interp
