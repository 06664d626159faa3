// Printable form of cycle steps, for golden tests and check-mode listings.

#include <fmt/format.h>

#include "interp/cycles.hpp"

namespace interp::cycles {
namespace {

std::string xyz(const Vec3& p) {
    return fmt::format("X{:g} Y{:g} Z{:g}", p[0], p[1], p[2]);
}

struct StepText {
    std::string operator()(const Rapid& s) const { return "rapid " + xyz(s.to_mm); }
    std::string operator()(const Feed& s) const {
        return fmt::format("feed {} F{:g}{}", xyz(s.to_mm), s.feed_mm_min,
                           s.override_locked ? " locked" : "");
    }
    std::string operator()(const Dwell& s) const { return fmt::format("dwell {:g}s", s.seconds); }
    std::string operator()(const SpindleStop&) const { return "spindle stop"; }
    std::string operator()(const SpindleOrient& s) const {
        return fmt::format("spindle orient tip=({:g} {:g} {:g})", s.tip_dir[0], s.tip_dir[1],
                           s.tip_dir[2]);
    }
    std::string operator()(const SpindleReverse&) const { return "spindle reverse"; }
    std::string operator()(const SpindleRestart&) const { return "spindle restart"; }
    std::string operator()(const SpindleCw&) const { return "spindle cw"; }
    std::string operator()(const SpindleSpeed& s) const {
        return fmt::format("spindle speed S{:g}", s.rpm);
    }
    std::string operator()(const OperatorRetract&) const { return "operator retract"; }
};

}  // namespace

std::string to_string(const Step& step) {
    return std::visit(StepText{}, step);
}

}  // namespace interp::cycles
