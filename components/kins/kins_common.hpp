// The HAL side every kinematics component shares: pins for the axes the machine has and for
// its joints, two realtime functions around a motion::Kinematics, and the entry point through
// which the motion component finds an instance (`loadrt motion kins=NAME`).
//
//   <inst>.inverse   axis.L.pos-cmd (in)  -> joint.N.pos-cmd (out)
//   <inst>.forward   joint.N.pos-fb (in)  -> axis.L.pos-fb (out)
//
// L is the lower-case axis letter (LinuxCNC's axis.x naming), N the joint number. Two
// functions rather than one so a servo thread can run inverse before the drives and forward
// after them, and see this cycle's feedback. A machine whose motion component uses the
// instance itself need not add either function to a thread.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "hal/component.hpp"
#include "motion/kinematics.hpp"

namespace kins {

inline constexpr char kAxisLetters[] = "xyzabcuvw";

namespace {

// This module's live instances, by name, for the motion component's kins= lookup.
// Configuration world only (loadrt, unload), hence the mutex. Internal linkage on purpose:
// one registry per kinematics .so, not one shared by all of them.
class Registry {
  public:
    void add(std::string name, std::shared_ptr<motion::KinematicsSource> source) {
        std::lock_guard lock(mutex_);
        entries_.push_back({std::move(name), std::move(source)});
    }
    void remove(std::string_view name) {
        std::lock_guard lock(mutex_);
        std::erase_if(entries_, [&](const Entry& e) { return e.name == name; });
    }
    // An instance by its name, or the module's only instance by the module's name.
    std::shared_ptr<motion::KinematicsSource> find(std::string_view name, std::string_view module) {
        std::lock_guard lock(mutex_);
        for (const Entry& e : entries_)
            if (e.name == name) return e.source;
        if (name == module && entries_.size() == 1) return entries_.front().source;
        return nullptr;
    }
    std::vector<std::string> names() {
        std::lock_guard lock(mutex_);
        std::vector<std::string> out;
        for (const Entry& e : entries_) out.push_back(e.name);
        return out;
    }

  private:
    struct Entry {
        std::string name;
        std::shared_ptr<motion::KinematicsSource> source;
    };
    std::mutex mutex_;
    std::vector<Entry> entries_;
};

Registry& registry() {
    static Registry r;
    return r;
}

}  // namespace

class KinsInstance : public hal::Instance {
  public:
    ~KinsInstance() override {
        if (!source_) return;
        source_->detach();  // a motion instance still using it keeps its last parameters
        registry().remove(name());
    }

  protected:
    // Called once from the derived constructor: makes the pins for the source's kinematics,
    // exports the functions and offers the source to the motion component. Configuration world.
    void build(std::shared_ptr<motion::KinematicsSource> source) {
        kins_ = source->make();
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
        registry().add(std::string(name()), source);
        source_ = std::move(source);
    }

  private:
    void inverse(hal::Period) noexcept {
        source_->refresh(*kins_);
        for (std::size_t i = 0; i < axes_.size(); ++i) axis_values_[axes_[i]] = *axis_cmd_[i];
        kins_->inverse(axis_values_, joints_);
        for (std::size_t j = 0; j < joints_.size(); ++j) *joint_cmd_[j] = joints_[j];
    }

    void forward(hal::Period) noexcept {
        source_->refresh(*kins_);
        for (std::size_t j = 0; j < joints_.size(); ++j) joints_[j] = *joint_fb_[j];
        kins_->forward(joints_, axis_values_);
        for (std::size_t i = 0; i < axes_.size(); ++i) *axis_fb_[i] = axis_values_[axes_[i]];
    }

    std::shared_ptr<motion::KinematicsSource> source_;
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

// The kinematics entry point of a kins .so (see motion::KinematicsModule); one per module,
// beside its HAL_COMPONENT line.
#define KINS_MODULE(NAME)                                                               \
    extern "C" __attribute__((visibility("default"))) const ::motion::KinematicsModule* \
    cnc_kinematics_module() {                                                           \
        static const ::motion::KinematicsModule module{                                 \
            ::motion::kKinematicsAbiVersion, #NAME,                                     \
            [](std::string_view n) { return ::kins::registry().find(n, #NAME); },       \
            [] { return ::kins::registry().names(); }};                                 \
        return &module;                                                                 \
    }
