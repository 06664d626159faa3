// The canonical-command sink of the motion component: motion commands become planner
// segments; dwells, program ends and every machine command (spindle, coolant, tool change,
// outputs, waits, pauses) become records that stand still in program order. Runs on the
// feeder thread.
#pragma once

#include <array>
#include <memory>
#include <optional>

#include "interp/canon.hpp"
#include "joint_limits.hpp"
#include "motion/planner.hpp"

namespace motioncomp {

struct FeederConfig;
class ProgramFeeder;

// What the sink checks a program against, from the component's params at start().
struct SinkConfig {
    motion::AxisArray min_limit_mm{};  // soft limits per axis (LinuxCNC axis.L.min-limit)
    motion::AxisArray max_limit_mm{};
    JointLimitConfig joints;  // joint soft limits, checked through the kinematics
    int digital_outputs = 4;  // motion.digital-out-NN count (num_dio=)
    int digital_inputs = 4;
};

// The canonical-command sink, plus what the feeder tells it after a conditional move (G904):
// the machine stopped at a place only known at run time, and the path goes on from there.
//
// Frames: the planner works in the frame the machine started in (the motors' frame); the program's
// machine coordinates differ from it by the shift each M902 sets (homing: "this point is now
// the home position"). The sink subtracts the shift from every end point, and the servo side
// adds it back on axis.L.pos-cmd, so the motors never jump.
class PlanSink : public interp::CanonSink {
  public:
    virtual void restart_from(const motion::AxisArray& pos_mm) = 0;  // planner frame
    // The machine coordinates of a planner-frame position, with the shifts the program has set
    // so far (the ones in force where the planning has got to).
    virtual motion::AxisArray to_machine(const motion::AxisArray& pos_mm) const = 0;
    // Where the machine stands (machine coordinates) once what is planned has run, when that is
    // not the end of a programmed move: after restart_from() until the next move. Otherwise
    // std::nullopt: it stands where the program last moved it.
    virtual std::optional<motion::AxisArray> standing_off_path_mm() const = 0;
};

std::unique_ptr<PlanSink> make_plan_sink(motion::Planner& planner, const FeederConfig& cfg,
                                         ProgramFeeder& feeder);

// The axis-aligned box of the points a segment from `start_mm` reaches after its start: its end
// and, for an arc, the extreme points of the circle it sweeps over. The start itself is left
// out so that a machine outside its soft limits may move back in (as LinuxCNC allows).
struct Extent {
    motion::AxisArray lo_mm{}, hi_mm{};
};
Extent segment_reach(const motion::AxisArray& start_mm, const motion::PathSegment& seg);

}  // namespace motioncomp
