// Turns the interpreter's canonical commands into planner input for the motion component.
#include "plan_sink.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <variant>

#include "canon_geometry.hpp"
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

constexpr char kLowerAxes[] = "xyzabcuvw";

// The committed canon::SpindleOrient may not carry an angle yet; 0 degrees then.
template <class Orient>
double orient_angle_deg(const Orient& o) {
    if constexpr (requires { o.tip_angle_deg; })
        return o.tip_angle_deg;
    else
        return 0.0;
}

// Turns canonical commands into planner input. Machine commands (spindle, coolant, tool
// change, outputs, waits, pauses) become action records after the motion before them has come
// to rest; commands this machine has nothing for (messages, latches, G904, clamps) are counted
// as ignored.
class PlanSink final : public interp::CanonSink {
  public:
    PlanSink(motion::Planner& planner, const FeederConfig& cfg, ProgramFeeder& feeder)
        : planner_(planner), cfg_(cfg), feeder_(feeder), pos_mm_(planner.end_position()) {}

    void emit(const interp::Canon& c) override {
        std::visit([&](const auto& cmd) { handle(c.loc, cmd); }, c.cmd);
    }

  private:
    void handle(const interp::SourceLoc& loc, const interp::canon::Traverse& t) {
        motion::PathSegment seg = base_segment(loc, t.end_mm, t.flags);
        seg.rapid = true;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::FeedLine& f) {
        motion::PathSegment seg = base_segment(loc, f.end_mm, f.flags);
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Arc& a) {
        motion::PathSegment seg = base_segment(loc, a.end_mm, a.flags);
        motioncomp::set_arc_geometry(seg, a);
        seg.feed_mm_s = feed_mm_s_;
        push(loc, seg);
    }
    // G61: tolerance 0, the planner's exact path (non-tangent corners are stopped at). G64 P:
    // that tolerance; G64 alone (or P0): the machine's, motion.blend-tolerance.
    void handle(const interp::SourceLoc&, const interp::canon::SetBlending& b) {
        if (b.exact)
            tolerance_mm_ = 0;
        else
            tolerance_mm_ = b.tolerance_mm > 0 ? b.tolerance_mm : cfg_.blend_tolerance_mm;
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
    // G906 without a port: motion comes to rest before the program goes on.
    void handle(const interp::SourceLoc&, const interp::canon::Sync&) {
        planner_.finish();
        feeder_.collect();
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::SetSpindleSpeed& s) {
        queue(loc, {motion::ActionKind::SpindleSpeed, false, 0, s.rpm});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Spindle& s) {
        const int dir = s.dir == interp::SpindleDir::Cw    ? 1
                        : s.dir == interp::SpindleDir::Ccw ? -1
                                                           : 0;
        queue(loc, {motion::ActionKind::Spindle, false, dir, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::SpindleOrient& o) {
        queue(loc, {motion::ActionKind::SpindleOrient, false, 0, orient_angle_deg(o)});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Coolant& c) {
        queue(loc, {motion::ActionKind::Coolant, c.flood, 0, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::ToolChange& t) {
        queue(loc, {motion::ActionKind::ToolChange, false, t.tool, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::SetToolNumber& t) {
        queue(loc, {motion::ActionKind::SetToolNumber, false, t.tool, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::SetOutput& o) {
        check_port(loc, "M901", "output", "digital-out", o.port, cfg_.machine.digital_outputs);
        queue(loc, {motion::ActionKind::SetOutput, o.level, o.port, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::WaitInput& w) {
        check_port(loc, "G906", "input", "digital-in", w.port, cfg_.machine.digital_inputs);
        queue(loc, {motion::ActionKind::WaitInput, w.level, w.port, w.timeout_s});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Stop& s) {
        queue(loc, {s.optional ? motion::ActionKind::OptionalPause : motion::ActionKind::Pause,
                    false, 0, 0});
    }
    // The end points include the tool length already; motion publishes it in program order
    // on motion.tooloffset.z for a kinematics that must know it (kins_xyzac_trt's tool-offset).
    void handle(const interp::SourceLoc& loc, const interp::canon::ToolOffset& t) {
        queue(loc, {motion::ActionKind::ToolOffset, false, 0, t.offset_mm[2]});
    }
    // Informational: end points already include offsets, units and plane are per move.
    void handle(const interp::SourceLoc&, const interp::canon::Offsets&) {}
    void handle(const interp::SourceLoc&, const interp::canon::Units&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SelectPlane&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedMode&) {}
    template <class Other>
    void handle(const interp::SourceLoc&, const Other&) {
        feeder_.count_ignored();
    }

    motion::PathSegment base_segment(const interp::SourceLoc& loc, const interp::AxisVec& end,
                                     const interp::canon::MoveFlags& flags) {
        motion::PathSegment seg;
        seg.end_mm = to_axes(end);
        seg.tolerance_mm = tolerance_mm_;
        seg.exact_stop = flags.exact_stop;  // G09
        seg.line = loc.line;
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k] && std::fabs(seg.end_mm[k] - pos_mm_[k]) > 1e-9)
                throw std::runtime_error(
                    fmt::format("{}:{}:{}: axis {} moves but the machine has only coordinates={}",
                                loc.file, loc.line, loc.col, kAxisLetters[k], cfg_.coordinates));
        }
        return seg;
    }

    // The motion so far ends at rest, then the action's record stands in the queue.
    void queue(const interp::SourceLoc& loc, const motion::Action& action) {
        planner_.finish();
        const motion::PreparedSegment rec = motion::action_record(pos_mm_, action, loc.line);
        feeder_.collect(&rec);
    }

    static void check_port(const interp::SourceLoc& loc, const char* code, const char* what,
                           const char* pin, int port, int count) {
        if (port >= 0 && port < count) return;
        throw std::runtime_error(
            fmt::format("{}:{}:{}: {}: {} {} does not exist: the machine has motion.{}-00 to {:02} "
                        "(num_dio={})",
                        loc.file, loc.line, loc.col, code, what, port, pin, count - 1, count));
    }

    // LinuxCNC refuses a move whose path leaves the soft limits before it starts; so does this.
    void check_soft_limits(const interp::SourceLoc& loc, const motion::PathSegment& seg) const {
        const Extent reach = segment_reach(pos_mm_, seg);
        constexpr double kSlack_mm = 1e-9;  // rounding of arc extremes computed from angles
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k]) continue;
            const double lo = cfg_.machine.min_limit_mm[k], hi = cfg_.machine.max_limit_mm[k];
            const bool low = reach.lo_mm[k] < lo - kSlack_mm;
            if (!low && reach.hi_mm[k] <= hi + kSlack_mm) continue;
            throw std::runtime_error(
                fmt::format("{}:{}:{}: the move takes {} to {} mm, which exceeds the soft limit "
                            "axis.{}.{}-limit = {} mm",
                            loc.file, loc.line, loc.col, kAxisLetters[k],
                            interp::fmt_num(low ? reach.lo_mm[k] : reach.hi_mm[k]), kLowerAxes[k],
                            low ? "min" : "max", interp::fmt_num(low ? lo : hi)));
        }
    }

    void push(const interp::SourceLoc& loc, const motion::PathSegment& seg) {
        check_soft_limits(loc, seg);
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
    double tolerance_mm_ = cfg_.blend_tolerance_mm;  // the G61/G64 mode in force
};

// Adds to `e` the points of the circle (centre c, radius r, in axes i, j) at the multiples of
// 90 degrees that a sweep of `sweep` radians from angle `from` passes.
void add_arc_extremes(Extent& e, int i, int j, double ci, double cj, double r, double from,
                      double sweep) {
    constexpr double kQuarter = std::numbers::pi / 2;
    const double lo = std::min(from, from + sweep), hi = std::max(from, from + sweep);
    for (double q = std::ceil(lo / kQuarter) * kQuarter; q <= hi; q += kQuarter) {
        const int quadrant = static_cast<int>(std::lround(q / kQuarter)) & 3;
        const double pi = ci + r * (quadrant == 0 ? 1 : quadrant == 2 ? -1 : 0);
        const double pj = cj + r * (quadrant == 1 ? 1 : quadrant == 3 ? -1 : 0);
        e.lo_mm[i] = std::min(e.lo_mm[i], pi);
        e.hi_mm[i] = std::max(e.hi_mm[i], pi);
        e.lo_mm[j] = std::min(e.lo_mm[j], pj);
        e.hi_mm[j] = std::max(e.hi_mm[j], pj);
    }
}

}  // namespace

Extent segment_reach(const motion::AxisArray& start, const motion::PathSegment& seg) {
    Extent e{seg.end_mm, seg.end_mm};
    if (seg.kind != motion::SegmentKind::Arc || seg.turns == 0) return e;
    const int i = seg.plane_first, j = seg.plane_second;
    const double ci = seg.centre_mm[0], cj = seg.centre_mm[1];
    const double from = std::atan2(start[j] - cj, start[i] - ci);
    const double to = std::atan2(seg.end_mm[j] - cj, seg.end_mm[i] - ci);
    // The planner may move the centre a little for an end slightly off the circle: take the
    // larger radius so the box never comes out smaller than the path.
    const double r = std::max(std::hypot(start[i] - ci, start[j] - cj),
                              std::hypot(seg.end_mm[i] - ci, seg.end_mm[j] - cj));
    constexpr double kTurn = 2 * std::numbers::pi;
    double sweep = seg.turns > 0 ? to - from : from - to;  // in the direction of travel, >= 0
    while (sweep <= 1e-12) sweep += kTurn;  // end == start in the plane: a full circle
    sweep += (std::abs(seg.turns) - 1) * kTurn;
    add_arc_extremes(e, i, j, ci, cj, r, from, seg.turns > 0 ? sweep : -sweep);
    return e;
}

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
