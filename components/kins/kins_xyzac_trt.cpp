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
//   tool-offset                tool length: the A axis is this much further from the tip
//   x-offset                   unused by XYZAC (LinuxCNC's XYZBC needs it); kept for porting
// LinuxCNC's formulas equal motion::XyzacTrtKinematics with c_pivot = (x-rot-point,
// y-rot-point) and a_pivot = (y-rot-point + y-offset, z-rot-point + z-offset + tool-offset),
// rotations right-handed in both. They are read every cycle, so motion may feed tool-offset.
#include "kins_common.hpp"

namespace {

struct KinsXyzacTrt : kins::KinsInstance {
    hal::In<double> x_rot_point{this, "x-rot-point"};
    hal::In<double> y_rot_point{this, "y-rot-point"};
    hal::In<double> z_rot_point{this, "z-rot-point"};
    hal::In<double> x_offset{this, "x-offset"};
    hal::In<double> y_offset{this, "y-offset"};
    hal::In<double> z_offset{this, "z-offset"};
    hal::In<double> tool_offset{this, "tool-offset"};
    motion::XyzacTrtKinematics* trt_ = nullptr;  // owned by the base

    KinsXyzacTrt() {
        auto k = std::make_unique<motion::XyzacTrtKinematics>(motion::TrtPivots{});
        trt_ = k.get();
        build(std::move(k));
    }

    void refresh() noexcept override {
        motion::TrtPivots p;
        p.c_pivot_mm = {x_rot_point, y_rot_point, 0.0};
        p.a_pivot_mm = {0.0, y_rot_point + y_offset, z_rot_point + z_offset + tool_offset};
        trt_->set_pivots(p);
    }
};

}  // namespace

HAL_COMPONENT(kins_xyzac_trt, KinsXyzacTrt,
              "Five-axis table-tilting kinematics (A on X, C on Z), LinuxCNC xyzac-trt-kins pins")
