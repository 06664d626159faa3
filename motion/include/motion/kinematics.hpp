// Kinematics: the map between axis coordinates (the programmed X Y Z A B C U V W, in mm and
// degrees) and joint positions (what each motor is commanded to). inverse() runs every servo
// period and forward() when feedback is turned into a position, so both are realtime-safe
// (noexcept, no allocation); constructors may throw and allocate.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "motion/types.hpp"

namespace motion {

class Kinematics {
  public:
    virtual ~Kinematics() = default;
    virtual std::string_view name() const noexcept = 0;
    // Number of joints, and for each joint the axis (0..8) whose limits, homing and feedback
    // display it belongs to.
    virtual std::span<const int> joint_axes() const noexcept = 0;
    std::size_t joint_count() const noexcept { return joint_axes().size(); }
    // joints.size() must equal joint_count().
    virtual void inverse(const AxisArray& axes, std::span<double> joints) const noexcept = 0;
    // Axes the machine does not have are left as they are in `axes`.
    virtual void forward(std::span<const double> joints, AxisArray& axes) const noexcept = 0;
};

// Axis index of a letter (X=0 ... W=8), or -1.
int axis_index(char letter) noexcept;

// LinuxCNC's trivkins: joint i follows the axis named by the i-th letter of `coordinates`
// ("XYZ", gantry "XYYZ": two joints on Y). forward() takes an axis from its first joint.
class TrivialKinematics final : public Kinematics {
  public:
    explicit TrivialKinematics(std::string_view coordinates);  // throws std::invalid_argument
    std::string_view name() const noexcept override { return "trivial"; }
    std::span<const int> joint_axes() const noexcept override { return axes_; }
    void inverse(const AxisArray& axes, std::span<double> joints) const noexcept override;
    void forward(std::span<const double> joints, AxisArray& axes) const noexcept override;

  private:
    std::vector<int> axes_;
};

// CoreXY: joint 0 = X + Y, joint 1 = X - Y, joint 2 = Z (belts of motors A and B).
class CoreXYKinematics final : public Kinematics {
  public:
    std::string_view name() const noexcept override { return "corexy"; }
    std::span<const int> joint_axes() const noexcept override { return axes_; }
    void inverse(const AxisArray& axes, std::span<double> joints) const noexcept override;
    void forward(std::span<const double> joints, AxisArray& axes) const noexcept override;

  private:
    static constexpr int axes_[3] = {0, 1, 2};
};

// Five-axis table-tilting machine (TRT) with a rotary A table (about a line parallel to X) that
// carries a rotary C table (about a line parallel to Z when A = 0). The program is in workpiece
// coordinates: the tool tip follows X Y Z as seen from the table. At A = C = 0 workpiece and
// machine coordinates coincide.
//
// A point fixed to the table at workpiece position p is carried to machine position
//     m = Ra(A) (Rc(C) (p - c_pivot) + c_pivot - a_pivot) + a_pivot
// where Rc rotates about +Z through c_pivot and Ra about +X through a_pivot, both right-handed
// (positive angle counter-clockwise seen from the positive axis). The joints are
// x y z = m, a = A, c = C; inverse() computes m, forward() inverts it.
struct TrtPivots {
    Eigen::Vector3d a_pivot_mm = Eigen::Vector3d::Zero();  // a point on the A rotation axis
    Eigen::Vector3d c_pivot_mm = Eigen::Vector3d::Zero();  // a point on the C axis at A = 0
};

class XyzacTrtKinematics final : public Kinematics {
  public:
    explicit XyzacTrtKinematics(const TrtPivots& pivots) : pv_(pivots) {}
    std::string_view name() const noexcept override { return "xyzac-trt"; }
    std::span<const int> joint_axes() const noexcept override { return axes_; }
    void inverse(const AxisArray& axes, std::span<double> joints) const noexcept override;
    void forward(std::span<const double> joints, AxisArray& axes) const noexcept override;
    void set_pivots(const TrtPivots& p) noexcept { pv_ = p; }

  private:
    static constexpr int axes_[5] = {0, 1, 2, 3, 5};
    TrtPivots pv_;
};

// Builds a kinematics by name: "trivial" (with coordinates), "corexy", "xyzac-trt".
std::unique_ptr<Kinematics> make_kinematics(std::string_view name, std::string_view coordinates,
                                            const TrtPivots& pivots = {});

}  // namespace motion
