// kins_trivial: LinuxCNC's trivkins as a HAL component (`loadrt kins_trivial
// [coordinates=XYZ]`): joint N follows the axis named by the N-th letter of coordinates; a
// letter given twice is a gantry (XYYZ: joints 1 and 2 both follow Y; Y's feedback comes from
// joint 1). Without coordinates= every axis letter gets a joint in order, as trivkins does.
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

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

// LinuxCNC's kinstype= (its first letter: 1 identity, B both, F forward only, I inverse only)
// tells LinuxCNC's motion whether joint and world mode coincide, for jogging and homing. Our
// motion has neither mode switch nor homing, so the value changes nothing; it is checked so a
// typo is not silently taken for identity, as LinuxCNC does.
void check_kinstype(const std::optional<std::string>& kinstype) {
    if (!kinstype) return;
    const std::string_view accepted = "1bBfFiI";
    if (kinstype->empty() || accepted.find(kinstype->front()) == std::string_view::npos)
        throw hal::Error("kinstype=" + *kinstype +
                         ": expected 1 (identity), B (both), F (forward only) or I (inverse only)");
}

struct KinsTrivial : kins::KinsInstance {
    KinsTrivial() {
        check_kinstype(arg("kinstype"));
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
              "coordinates", "kinstype")
KINS_MODULE(kins_trivial)
