// The geometry of a canonical arc as a planner segment: the one place where the interpreter's
// plane and centre become the planner's. Shared by the motion component's sink and the planner
// benchmark (tests/bench_motion), which feed the same planner from the same canonical stream.
#pragma once

#include "interp/canon.hpp"
#include "motion/types.hpp"

namespace motioncomp {

// Sets kind, plane, centre and turns; end point, feed, tolerance and line are the caller's.
inline void set_arc_geometry(motion::PathSegment& seg, const interp::canon::Arc& a) {
    seg.kind = motion::SegmentKind::Arc;
    const interp::PlaneAxes axes = interp::plane_axes(a.plane);
    seg.plane_first = axes.first;
    seg.plane_second = axes.second;
    seg.plane_normal = axes.normal;
    seg.centre_mm = {a.centre_mm[axes.first], a.centre_mm[axes.second]};
    seg.turns = a.turns;
}

}  // namespace motioncomp
