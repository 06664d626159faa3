// kins_corexy: CoreXY belt kinematics (`loadrt kins_corexy`): joint 0 = X + Y,
// joint 1 = X - Y, joint 2 = Z.
#include "kins_common.hpp"

namespace {

struct KinsCoreXY : kins::KinsInstance {
    KinsCoreXY() { build(std::make_unique<motion::CoreXYKinematics>()); }
};

}  // namespace

HAL_COMPONENT(kins_corexy, KinsCoreXY,
              "CoreXY kinematics: joint 0 = X + Y, joint 1 = X - Y, joint 2 = Z")
