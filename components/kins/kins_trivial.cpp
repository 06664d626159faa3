// kins_trivial: LinuxCNC's trivkins as a HAL component (`loadrt kins_trivial
// [coordinates=XYZ]`): joint N follows the axis named by the N-th letter of coordinates; a
// letter given twice is a gantry (XYYZ: joints 1 and 2 both follow Y; Y's feedback comes from
// joint 1). Without coordinates= every axis letter gets a joint in order, as trivkins does.
#include <stdexcept>

#include "kins_common.hpp"

namespace {

class TrivialSource final : public motion::KinematicsSource {
  public:
    explicit TrivialSource(std::string coordinates) : coordinates_(std::move(coordinates)) {}
    std::unique_ptr<motion::Kinematics> make() const override {
        return std::make_unique<motion::TrivialKinematics>(coordinates_);
    }

  private:
    std::string coordinates_;
};

struct KinsTrivial : kins::KinsInstance {
    KinsTrivial() {
        const std::string coordinates = arg("coordinates").value_or("XYZABCUVW");
        try {
            build(std::make_shared<TrivialSource>(coordinates));
        } catch (const std::invalid_argument& e) {
            throw hal::Error(e.what());
        }
    }
};

}  // namespace

HAL_COMPONENT(kins_trivial, KinsTrivial,
              "Trivial kinematics: joint N follows the N-th letter of coordinates= (gantry: a "
              "letter twice)",
              "coordinates")
KINS_MODULE(kins_trivial)
