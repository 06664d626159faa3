// G904's result into the interpreter's model, one implementation for both ways a machine runs
// programs: the interp component's runner (which reads motion.probe-pos-L and
// motion.probe-tripped at the barrier it sends after a G904) and motion's own program feeder
// (program=, told by the servo function). Configuration world: the interpreter's thread.
#pragma once

#include "interp/block.hpp"
#include "interp/canon.hpp"
#include "interp/executor.hpp"

namespace machine_program {

// The watched axes of `cm` take `trip_mm(axis)` (axis 0..2 = X Y Z), the machine coordinate
// where that axis's input came, or where it stopped if it never came. The model takes the
// trip point, not the stop a braking distance beyond it, so an incremental move after the G904
// is measured from the touch (the manual's tool-setting routine relies on it); #CURMACHPOS
// still reads where the machine stands. A move that ended without all its inputs (`tripped`
// false) is NCX-3's alarm: interp::Error at `loc`, thrown after the model has taken the
// position.
template <class TripAt>
void adopt_probe_result(interp::Executor& exec, const interp::SourceLoc& loc,
                        const interp::canon::ConditionalMove& cm, bool tripped,
                        const TripAt& trip_mm) {
    interp::AxisVec pos{};
    unsigned axes = 0;
    for (const auto& w : cm.axes) {
        if (!w) continue;
        pos[w->axis] = trip_mm(w->axis);
        axes |= 1u << w->axis;
    }
    exec.adopt_machine_position(pos, axes);
    if (!tripped) throw interp::Error(loc, interp::untripped_message(cm, pos));
}

}  // namespace machine_program
