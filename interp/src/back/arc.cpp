#include "interp/arc.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "interp/canon.hpp"

namespace interp {

namespace {

constexpr double kSamePoint = 1e-9;

double sweep_between(const Eigen::Vector2d& c, const Eigen::Vector2d& s, const Eigen::Vector2d& e,
                     bool ccw) {
    // One atan2 of the angle between the radii (counter-clockwise, in (-pi, pi]) instead of two
    // absolute angles: arcs are a third of a typical program and atan2 was a visible cost.
    const Eigen::Vector2d a = s - c, b = e - c;
    double d = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    if (!ccw) d = -d;
    if (d <= 0) d += 2 * std::numbers::pi;
    return d;
}

std::string solve_r(const ArcInput& in, ArcResult& out) {
    const double r_signed = *in.radius;
    const Eigen::Vector2d chord = in.end - in.start;
    const double d = chord.norm();
    if (d < kSamePoint) return "a full circle cannot be programmed with R; use I/J/K";
    if (r_signed == 0) return "arc radius R0";
    double r = std::abs(r_signed);
    if (r < d / 2 - in.tolerance_mm) {
        if (!in.v54_small_radius_is_half_circle)
            return fmt::format("arc radius R{} is smaller than half the chord ({} mm)", fmt_num(r),
                               fmt_num(d / 2));
        r = d / 2;
    }
    r = std::max(r, d / 2);
    const double h = std::sqrt(std::max(0.0, r * r - d * d / 4));
    const Eigen::Vector2d u = chord / d;
    const Eigen::Vector2d left(-u.y(), u.x());
    // A short counter-clockwise arc has its centre on the left of the chord; G02 and R<0 each
    // move it to the other side.
    const double side = (in.ccw ? 1.0 : -1.0) * (r_signed < 0 ? -1.0 : 1.0);
    out.centre = (in.start + in.end) / 2 + side * h * left;
    out.radius_mm = r;
    if (in.want_sweep) out.sweep_rad = sweep_between(out.centre, in.start, in.end, in.ccw);
    return {};
}

std::string solve_centre(const ArcInput& in, ArcResult& out) {
    const Eigen::Vector2d c = *in.centre;
    const double r0 = (in.start - c).norm();
    const double r1 = (in.end - c).norm();
    if (r0 < kSamePoint) return "arc radius is zero (centre at the start point)";
    if (std::abs(r0 - r1) > in.tolerance_mm)
        return fmt::format(
            "arc end point is not on the circle: radius {} mm at the start, {} mm at the end "
            "(difference {} mm, tolerance {} mm)",
            fmt_num(r0), fmt_num(r1), fmt_num(std::abs(r0 - r1)), fmt_num(in.tolerance_mm));
    out.centre = c;
    out.radius_mm = r0;
    if (!in.want_sweep) return {};
    out.sweep_rad = (in.end - in.start).norm() < kSamePoint
                        ? 2 * std::numbers::pi
                        : sweep_between(c, in.start, in.end, in.ccw);
    return {};
}

}  // namespace

std::string solve_arc(const ArcInput& in, ArcResult& out) {
    if (in.radius) return solve_r(in, out);
    if (in.centre) return solve_centre(in, out);
    return "arc needs R or I/J/K";
}

}  // namespace interp
