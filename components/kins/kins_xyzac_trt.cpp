// kins_xyzac_trt: five-axis table-tilting kinematics (`loadrt kins_xyzac_trt`): an A table
// rotating about a line parallel to X carries a C table rotating about a line parallel to Z
// (at A = 0). Axes X Y Z are the tool tip in workpiece coordinates; joints 0-2 are the linear
// machine axes, joint 3 is A and joint 4 is C (degrees).
//
// The geometry comes in through LinuxCNC's xyzac-trt-kins pins, with the same meaning, so a
// LinuxCNC config ports by naming the instance xyzac-trt-kins:
//   x-rot-point, y-rot-point   where the C axis crosses the XY plane (at A = 0)
//   y-offset                   the A axis lies y-offset from y-rot-point in Y ...
//   z-rot-point + z-offset     ... and at this Z
//   tool-offset                tool length (net motion.tooloffset.z to it, as LinuxCNC
//                              configs do): the program's Z includes it (G43), and adding it
//                              to the A pivot makes the tool tip, not the spindle nose,
//                              follow the path when A tilts (see motion/kinematics.hpp)
//   x-offset                   unused by XYZAC (LinuxCNC's XYZBC needs it); kept for porting
// LinuxCNC's formulas equal motion::XyzacTrtKinematics with c_pivot = (x-rot-point,
// y-rot-point) and a_pivot = (y-rot-point + y-offset, z-rot-point + z-offset + tool-offset),
// rotations right-handed in both. They are read every cycle, so tool-offset follows G43/G49 as the
// program runs.
#include "kins_common.hpp"

namespace {

// The geometry pins; shared with the motion component through the registry, so they are
// members of the source rather than of the instance.
class TrtSource final : public motion::KinematicsSource {
  public:
    explicit TrtSource(hal::Instance* owner)
        : x_rot_point_(owner, "x-rot-point"),
          y_rot_point_(owner, "y-rot-point"),
          z_rot_point_(owner, "z-rot-point"),
          x_offset_(owner, "x-offset"),
          y_offset_(owner, "y-offset"),
          z_offset_(owner, "z-offset"),
          tool_offset_(owner, "tool-offset") {}

    std::unique_ptr<motion::Kinematics> make() const override {
        return std::make_unique<motion::XyzacTrtKinematics>(motion::TrtPivots{});
    }

  private:
    void copy_params(motion::Kinematics& k) const noexcept override {
        copy_params_with_tool_offset(k, tool_offset_);
    }
    void copy_params_with_tool_offset(motion::Kinematics& k,
                                      double tool_offset_mm) const noexcept override {
        motion::TrtPivots p;
        p.c_pivot_mm = {x_rot_point_, y_rot_point_, 0.0};
        p.a_pivot_mm = {0.0, y_rot_point_ + y_offset_, z_rot_point_ + z_offset_ + tool_offset_mm};
        static_cast<motion::XyzacTrtKinematics&>(k).set_pivots(p);  // k came from make()
    }

    hal::In<double> x_rot_point_, y_rot_point_, z_rot_point_;
    hal::In<double> x_offset_, y_offset_, z_offset_;
    hal::In<double> tool_offset_;
};

struct KinsXyzacTrt : kins::KinsInstance {
    KinsXyzacTrt() { build(std::make_shared<TrtSource>(this)); }
};

}  // namespace

HAL_COMPONENT(kins_xyzac_trt, KinsXyzacTrt,
              "Five-axis table-tilting kinematics (A on X, C on Z), LinuxCNC xyzac-trt-kins pins")
KINS_MODULE(kins_xyzac_trt)
