// The HAL side every kinematics component shares: pins for the axes the machine has and for
// its joints, and two realtime functions around a motion::Kinematics.
//
//   <inst>.inverse   axis.L.pos-cmd (in)  -> joint.N.pos-cmd (out)
//   <inst>.forward   joint.N.pos-fb (in)  -> axis.L.pos-fb (out)
//
// L is the lower-case axis letter (LinuxCNC's axis.x naming), N the joint number. Two
// functions rather than one so a servo thread can run inverse before the drives and forward
// after them, and see this cycle's feedback.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "hal/component.hpp"
#include "motion/kinematics.hpp"

namespace kins {

inline constexpr char kAxisLetters[] = "xyzabcuvw";

class KinsInstance : public hal::Instance {
  protected:
    // Called once from the derived constructor: makes the pins for `k` and exports the
    // functions. Configuration world.
    void build(std::unique_ptr<motion::Kinematics> k) {
        kins_ = std::move(k);
        std::vector<bool> present(motion::kAxes, false);
        for (int axis : kins_->joint_axes()) present[axis] = true;
        for (int axis = 0; axis < motion::kAxes; ++axis) {
            if (!present[axis]) continue;
            const std::string stem = std::string("axis.") + kAxisLetters[axis];
            axes_.push_back(axis);
            axis_cmd_.push_back(std::make_unique<hal::In<double>>(this, stem + ".pos-cmd"));
            axis_fb_.push_back(std::make_unique<hal::Out<double>>(this, stem + ".pos-fb"));
        }
        for (std::size_t j = 0; j < kins_->joint_count(); ++j) {
            const std::string stem = "joint." + std::to_string(j);
            joint_cmd_.push_back(std::make_unique<hal::Out<double>>(this, stem + ".pos-cmd"));
            joint_fb_.push_back(std::make_unique<hal::In<double>>(this, stem + ".pos-fb"));
        }
        joints_.assign(kins_->joint_count(), 0.0);
        function<&KinsInstance::inverse>("inverse");
        function<&KinsInstance::forward>("forward");
    }

    // Realtime hook run before each conversion: a component with params copies them into its
    // kinematics here.
    virtual void refresh() noexcept {}

  private:
    void inverse(hal::Period) noexcept {
        refresh();
        for (std::size_t i = 0; i < axes_.size(); ++i) axis_values_[axes_[i]] = *axis_cmd_[i];
        kins_->inverse(axis_values_, joints_);
        for (std::size_t j = 0; j < joints_.size(); ++j) *joint_cmd_[j] = joints_[j];
    }

    void forward(hal::Period) noexcept {
        refresh();
        for (std::size_t j = 0; j < joints_.size(); ++j) joints_[j] = *joint_fb_[j];
        kins_->forward(joints_, axis_values_);
        for (std::size_t i = 0; i < axes_.size(); ++i) *axis_fb_[i] = axis_values_[axes_[i]];
    }

    std::unique_ptr<motion::Kinematics> kins_;
    std::vector<int> axes_;  // axis indices the machine has, ascending
    std::vector<std::unique_ptr<hal::In<double>>> axis_cmd_;
    std::vector<std::unique_ptr<hal::Out<double>>> axis_fb_;
    std::vector<std::unique_ptr<hal::Out<double>>> joint_cmd_;
    std::vector<std::unique_ptr<hal::In<double>>> joint_fb_;
    std::vector<double> joints_;       // scratch, sized once in build()
    motion::AxisArray axis_values_{};  // scratch
};

}  // namespace kins
