// kins_corexy: CoreXY belt kinematics (`loadrt kins_corexy [joints=N]`): joint 0 = X + Y,
// joint 1 = X - Y, joint 2 = Z. As with LinuxCNC's corexykins, a machine with more joints
// (joints=4..9) has joints 3-8 follow A B C U V W one to one.
#include <stdexcept>
#include <string>

#include "kins_common.hpp"

namespace {

// CoreXY on joints 0-2 plus identity joints for A..W: motion::CoreXYKinematics knows only the
// first three, so the extra joints are mapped here.
class CoreXYWithExtras final : public motion::Kinematics {
  public:
    explicit CoreXYWithExtras(int joints) {
        for (int j = 0; j < joints; ++j) axes_.push_back(j);  // joint j <-> axis j for XYZABCUVW
    }
    std::string_view name() const noexcept override { return "corexy"; }
    std::span<const int> joint_axes() const noexcept override { return axes_; }
    void inverse(const motion::AxisArray& axes, std::span<double> joints) const noexcept override {
        core_.inverse(axes, joints.first(3));
        for (std::size_t j = 3; j < axes_.size(); ++j) joints[j] = axes[axes_[j]];
    }
    void forward(std::span<const double> joints, motion::AxisArray& axes) const noexcept override {
        core_.forward(joints.first(3), axes);
        for (std::size_t j = 3; j < axes_.size(); ++j) axes[axes_[j]] = joints[j];
    }
    std::vector<motion::AxisArray> linear_map() const override {
        std::vector<motion::AxisArray> rows = core_.linear_map();
        rows.resize(axes_.size(), motion::AxisArray{});
        for (std::size_t j = 3; j < axes_.size(); ++j)
            rows[j][static_cast<std::size_t>(axes_[j])] = 1;
        return rows;
    }

  private:
    motion::CoreXYKinematics core_;
    std::vector<int> axes_;
};

class CoreXYSource final : public motion::KinematicsSource {
  public:
    explicit CoreXYSource(int joints) : joints_(joints) {}
    std::unique_ptr<motion::Kinematics> make() const override {
        return std::make_unique<CoreXYWithExtras>(joints_);
    }

  private:
    int joints_;
};

struct KinsCoreXY : kins::KinsInstance {
    KinsCoreXY() {
        const long joints = arg_int("joints", 3);
        if (joints < 3 || joints > motion::kAxes)
            throw hal::Error("joints=" + std::to_string(joints) + ": give 3 to 9 joints");
        build(std::make_shared<CoreXYSource>(static_cast<int>(joints)));
    }
};

}  // namespace

HAL_COMPONENT(kins_corexy, KinsCoreXY,
              "CoreXY kinematics: joint 0 = X + Y, joint 1 = X - Y, joint 2 = Z, joints 3-8 A..W",
              "joints")
KINS_MODULE(kins_corexy)
