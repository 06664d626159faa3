// Kinematics: the map between axis coordinates (the programmed X Y Z A B C U V W, in mm and
// degrees) and joint positions (what each motor is commanded to). inverse() runs every servo
// period and forward() when feedback is turned into a position, so both are realtime-safe
// (noexcept, no allocation); constructors may throw and allocate.
#pragma once

#include <Eigen/Geometry>
#include <atomic>
#include <cstdint>
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
    // For a kinematics whose joints are a constant linear map of the axes, q = M p (trivial,
    // gantry, CoreXY): M's rows, one per joint, so that the planner can keep the joints within
    // their limits (set_linear_joints(), limits.hpp). Empty for any other kinematics (a tilting
    // table's joints depend on the angles): its joint velocities and accelerations are only
    // checked as they are commanded, as in LinuxCNC. Configuration world.
    virtual std::vector<AxisArray> linear_map() const { return {}; }
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
    std::vector<AxisArray> linear_map() const override;

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
    std::vector<AxisArray> linear_map() const override;

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

// Tool length for XyzacTrtKinematics: the program's end points include the tool length offset
// in Z (G43), i.e. they are the spindle nose, tool_length_mm above the tip along the workpiece
// Z. With the table tilted the tool still hangs along the machine Z, so the nose must sit
// tool_length_mm above the tip along the *machine* Z. Moving the A pivot up by the same
// length does exactly that (LinuxCNC's xyzac-trt-kins adds its tool-offset pin to the pivot
// Z the same way): for nose = tip + L z,  Rc(nose - c) = Rc(tip - c) + L z, so
//     m(nose, a_pivot + L z) = m(tip, a_pivot) + L z   for every A and C.
// The pivots given to set_pivots() already include it; see kins_xyzac_trt's tool-offset pin.

// ---- Kinematics modules in HAL --------------------------------------------------------------
//
// A kinematics .so (components/kins/*) is a HAL component whose instances carry a machine's
// geometry on pins. The motion component uses one with `loadrt motion kins=NAME`, the way
// LinuxCNC's motmod calls the kins module loaded before it: it asks the module for the
// KinematicsSource of the instance NAME, builds its own Kinematics with make() and calls
// refresh() and inverse() every servo period.

// What a kinematics module's instance offers to another component. Shared between the
// instance and its users (shared_ptr), so it outlives an instance that is unloaded first.
class KinematicsSource {
  public:
    virtual ~KinematicsSource() = default;
    // Configuration world: a kinematics of this machine, for the caller to own.
    virtual std::unique_ptr<Kinematics> make() const = 0;
    // Realtime: copies the instance's current parameters (its pins) into `k`, which make()
    // built. Returns false, touching nothing, once the instance has been unloaded; `k` then
    // keeps the last parameters.
    bool refresh(Kinematics& k) const noexcept {
        if (!attached_.load(std::memory_order_acquire)) return false;
        copy_params(k);
        return true;
    }
    // Any thread, for a kinematics `k` of the caller's own (never the one a servo function
    // refreshes): refresh() with `tool_offset_mm` in place of the instance's tool length input,
    // so a planner can map a move through the kinematics with the tool offset (G43) it will run
    // with. A kinematics without a tool length ignores it. Returns false, touching nothing, once
    // the instance has been unloaded.
    bool refresh_with_tool_offset(Kinematics& k, double tool_offset_mm) const noexcept {
        if (!attached_.load(std::memory_order_acquire)) return false;
        copy_params_with_tool_offset(k, tool_offset_mm);
        return true;
    }
    // Configuration world: called by the instance's destructor, before its pins go.
    void detach() noexcept { attached_.store(false, std::memory_order_release); }

  protected:
    // Realtime: reads the pins into `k` (a kinematics from make()). Default: no parameters.
    virtual void copy_params(Kinematics&) const noexcept {}
    // As copy_params(), with the tool length given instead of read. Default: copy_params().
    virtual void copy_params_with_tool_offset(Kinematics& k, double) const noexcept {
        copy_params(k);
    }

  private:
    std::atomic<bool> attached_{true};
};

// The C entry point every kinematics .so exports beside cnc_hal_component:
//     extern "C" const motion::KinematicsModule* cnc_kinematics_module();
inline constexpr char kKinematicsEntryPoint[] = "cnc_kinematics_module";
// 2: KinematicsSource gained copy_params_with_tool_offset (its vtable changed).
// 3: Kinematics gained linear_map (its vtable changed).
inline constexpr std::uint32_t kKinematicsAbiVersion = 3;

struct KinematicsModule {
    std::uint32_t abi_version;  // first, and kept first by every future version
    const char* name;           // the module: "kins_corexy"
    // The source of this module's instance named `name`, or of its only instance when `name`
    // is the module's name; null when there is none. Configuration world.
    std::shared_ptr<KinematicsSource> (*find)(std::string_view name);
    // The names of the module's live instances, for error messages.
    std::vector<std::string> (*instances)();
};

// Builds a kinematics by name: "trivial" (with coordinates), "corexy", "xyzac-trt".
std::unique_ptr<Kinematics> make_kinematics(std::string_view name, std::string_view coordinates,
                                            const TrtPivots& pivots = {});

}  // namespace motion
