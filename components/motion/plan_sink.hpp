// The canonical-command sink of the motion component: motion commands become planner
// segments, dwells and program ends become records that hold still. Runs on the feeder thread.
#pragma once

#include <memory>

#include "interp/canon.hpp"
#include "motion/planner.hpp"

namespace motioncomp {

struct FeederConfig;
class ProgramFeeder;

std::unique_ptr<interp::CanonSink> make_plan_sink(motion::Planner& planner, const FeederConfig& cfg,
                                                  ProgramFeeder& feeder);

}  // namespace motioncomp
