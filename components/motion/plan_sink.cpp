// Turns the interpreter's canonical commands into planner input for the motion component.
#include "plan_sink.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <variant>

#include "interp/canon.hpp"
#include "program_feeder.hpp"

namespace motioncomp {

namespace {

constexpr char kAxisLetters[] = "XYZABCUVW";

// The interpreter's machine axes (X Y Z A B C) are the first of the planner's nine.
motion::AxisArray to_axes(const interp::AxisVec& v) {
    motion::AxisArray out{};
    for (int k = 0; k < interp::kMachineAxes && k < motion::kAxes; ++k) out[k] = v[k];
    return out;
}

// Turns canonical commands into planner input. Commands without a motion meaning for this
// component (spindle, coolant, I/O, tool changes, waits, messages) are counted, not obeyed.
class PlanSink final : public interp::CanonSink {
  public:
    PlanSink(motion::Planner& planner, const FeederConfig& cfg, ProgramFeeder& feeder)
        : planner_(planner), cfg_(cfg), feeder_(feeder), pos_mm_(planner.end_position()) {}

    void emit(const interp::Canon& c) override {
        std::visit([&](const auto& cmd) { handle(c.loc, cmd); }, c.cmd);
    }

  private:
    void handle(const interp::SourceLoc& loc, const interp::canon::Traverse& t) {
        motion::PathSegment seg = base_segment(loc, t.end_mm);
        seg.rapid = true;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::FeedLine& f) {
        motion::PathSegment seg = base_segment(loc, f.end_mm);
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Arc& a) {
        motion::PathSegment seg = base_segment(loc, a.end_mm);
        seg.kind = motion::SegmentKind::Arc;
        const interp::PlaneAxes axes = interp::plane_axes(a.plane);
        seg.plane_first = axes.first;
        seg.plane_second = axes.second;
        seg.plane_normal = axes.normal;
        seg.centre_mm = {a.centre_mm[axes.first], a.centre_mm[axes.second]};
        seg.turns = a.turns;
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedRate& f) {
        feed_mm_s_ = f.feed_mm_s;
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Dwell& d) {
        // The planner has no pause element: end the motion at rest, then queue a record that
        // stands still for the dwell time.
        planner_.finish();
        if (d.seconds > 0) {
            const motion::PreparedSegment rec =
                dwell_record(pos_mm_, d.seconds, loc.line, cfg_.plan.max_rate);
            feeder_.collect(&rec);
        } else {
            feeder_.collect();
        }
    }
    void handle(const interp::SourceLoc&, const interp::canon::ProgramEnd&) {
        planner_.finish();
        feeder_.collect();
    }
    // Informational: end points already include offsets, units and plane are per move.
    void handle(const interp::SourceLoc&, const interp::canon::Offsets&) {}
    void handle(const interp::SourceLoc&, const interp::canon::ToolOffset&) {}
    void handle(const interp::SourceLoc&, const interp::canon::Units&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SelectPlane&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedMode&) {}
    template <class Other>
    void handle(const interp::SourceLoc&, const Other&) {
        feeder_.count_ignored();
    }

    motion::PathSegment base_segment(const interp::SourceLoc& loc, const interp::AxisVec& end) {
        motion::PathSegment seg;
        seg.end_mm = to_axes(end);
        seg.tolerance_mm = cfg_.blend_tolerance_mm;
        seg.line = loc.line;
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k] && std::fabs(seg.end_mm[k] - pos_mm_[k]) > 1e-9)
                throw std::runtime_error(
                    fmt::format("{}:{}:{}: axis {} moves but the machine has only coordinates={}",
                                loc.file, loc.line, loc.col, kAxisLetters[k], cfg_.coordinates));
        }
        return seg;
    }

    void push(const interp::SourceLoc& loc, const motion::PathSegment& seg) {
        try {
            planner_.push(seg);
        } catch (const motion::PlanError& e) {
            // PlanError says "line N: reason"; the user needs the file too.
            std::string reason = e.what();
            const auto colon = reason.find(": ");
            if (colon != std::string::npos) reason.erase(0, colon + 2);
            throw std::runtime_error(
                fmt::format("{}:{}:{}: {}", loc.file, loc.line, loc.col, reason));
        }
        pos_mm_ = seg.end_mm;
        feeder_.collect();
    }

    motion::Planner& planner_;
    const FeederConfig& cfg_;
    ProgramFeeder& feeder_;
    motion::AxisArray pos_mm_;
    double feed_mm_s_ = 0;
};

}  // namespace

std::unique_ptr<interp::CanonSink> make_plan_sink(motion::Planner& planner, const FeederConfig& cfg,
                                                  ProgramFeeder& feeder) {
    return std::make_unique<PlanSink>(planner, cfg, feeder);
}

motion::PreparedSegment dwell_record(const motion::AxisArray& pos_mm, double seconds,
                                     std::int32_t line, double max_rate) {
    motion::PreparedSegment rec{};
    rec.geom = motion::make_line(pos_mm, pos_mm);
    rec.profile.count = 1;  // one phase at rest: s = 0 throughout
    rec.profile.duration_s = seconds;
    rec.phase_rate_cap.fill(max_rate);  // nothing moves, so no rate can exceed a limit
    rec.line = line;
    rec.program_end = true;
    return rec;
}

}  // namespace motioncomp
