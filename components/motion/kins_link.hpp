// The kinematics a motion instance runs every servo period: LinuxCNC's trivkins built in
// (joint N follows the N-th letter of coordinates=), or the machine's kinematics module
// loaded earlier in the HAL file and named by `kins=` (an instance name, or a module name
// loaded once), as LinuxCNC's motmod uses the kins module loaded before it.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "motion/kinematics.hpp"

namespace motioncomp {

class KinsLink {
  public:
    // Configuration world; both throw hal::Error with the reason.
    static KinsLink builtin(std::string_view coordinates);
    static KinsLink find(std::string_view name);
    // kins=auto, LinuxCNC motmod's rule: the one kinematics instance loaded before motion, or
    // the built-in trivial kinematics of `coordinates` when none is; two or more is an error
    // naming them.
    static KinsLink automatic(std::string_view coordinates);

    KinsLink(KinsLink&&) noexcept;
    KinsLink& operator=(KinsLink&&) = delete;
    KinsLink(const KinsLink&) = delete;
    ~KinsLink();

    motion::Kinematics& kins() noexcept { return *kins_; }
    const motion::Kinematics& kins() const noexcept { return *kins_; }
    // Realtime: reads the module's parameters (pivots, tool offset) into kins(). False once
    // the module's instance has been unloaded (kins() keeps the last parameters).
    bool refresh() noexcept { return !source_ || source_->refresh(*kins_); }
    // "trivial" or the name of the instance used.
    const std::string& name() const noexcept { return name_; }
    // True when a loaded kinematics instance computes the joints, false for the built-in one.
    bool from_module() const noexcept { return source_ != nullptr; }
    // Configuration world. LinuxCNC's trivkins without coordinates= drives all nine axes
    // XYZABCUVW, one joint each, and motmod's num_joints says how many of those joints exist:
    // keeps the first n (1 to 8) joints of such a kinematics and returns true; false, changing
    // nothing, for any other kinematics (a gantry's XYYZ must match num_joints exactly).
    bool keep_first_joints_of_identity(std::size_t n);

  private:
    KinsLink() = default;
    std::string name_;
    void* library_ = nullptr;  // a dlopen reference that keeps the module's code mapped
    std::shared_ptr<motion::KinematicsSource> source_;
    std::unique_ptr<motion::Kinematics> kins_;
};

}  // namespace motioncomp
