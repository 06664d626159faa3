// kins_xyzac_trt: five-axis table-tilting kinematics (`loadrt kins_xyzac_trt`): an A table
// rotating about a line parallel to X carries a C table rotating about a line parallel to Z
// (at A = 0). Axes X Y Z are the tool tip in workpiece coordinates; joints 0-2 are the linear
// machine axes, joint 3 is A and joint 4 is C (degrees). The pivot lines are params, read
// every cycle so they can be changed while running:
//   a-pivot-y, a-pivot-z   where the A axis crosses the machine's YZ plane
//   c-pivot-x, c-pivot-y   where the C axis crosses the XY plane when A = 0
// (the other coordinates of each line do not change the mapping).
#include "kins_common.hpp"

namespace {

struct KinsXyzacTrt : kins::KinsInstance {
    hal::Param<double> a_pivot_y{this, "a-pivot-y", 0.0};
    hal::Param<double> a_pivot_z{this, "a-pivot-z", 0.0};
    hal::Param<double> c_pivot_x{this, "c-pivot-x", 0.0};
    hal::Param<double> c_pivot_y{this, "c-pivot-y", 0.0};
    motion::XyzacTrtKinematics* trt_ = nullptr;  // owned by the base

    KinsXyzacTrt() {
        auto k = std::make_unique<motion::XyzacTrtKinematics>(motion::TrtPivots{});
        trt_ = k.get();
        build(std::move(k));
    }

    void refresh() noexcept override {
        motion::TrtPivots p;
        p.a_pivot_mm = {0.0, a_pivot_y, a_pivot_z};
        p.c_pivot_mm = {c_pivot_x, c_pivot_y, 0.0};
        trt_->set_pivots(p);
    }
};

}  // namespace

HAL_COMPONENT(kins_xyzac_trt, KinsXyzacTrt,
              "Five-axis table-tilting kinematics (A on X, C on Z) with pivot params")
