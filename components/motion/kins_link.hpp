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

// The machine's kinematics for the non-realtime planner thread: an object of its own, since the
// servo thread's (KinsLink::kins()) is refreshed from the module's pins every period. Its
// parameters are the module's at the time it was made, except the tool length, which follows
// the program (set_tool_offset) rather than the pin the servo side changes when the move runs.
class PlanningKinematics {
  public:
    PlanningKinematics(std::shared_ptr<const motion::KinematicsSource> source,
                       std::unique_ptr<motion::Kinematics> kins)
        : source_(std::move(source)), kins_(std::move(kins)) {}
    const motion::Kinematics& kins() const noexcept { return *kins_; }
    // The tool length offset in Z (G43/G49) the moves planned from now on run with: what motion
    // writes on motion.tooloffset.z, which a TRT config nets to the kinematics' tool-offset.
    void set_tool_offset(double tool_offset_mm) noexcept {
        if (source_) source_->refresh_with_tool_offset(*kins_, tool_offset_mm);
    }

  private:
    std::shared_ptr<const motion::KinematicsSource> source_;  // null: the built-in kinematics
    std::unique_ptr<motion::Kinematics> kins_;
};

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
    // Configuration world: a second kinematics of this machine with the module's current
    // parameters, for the planner thread.
    std::unique_ptr<PlanningKinematics> planning_copy() const;
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
