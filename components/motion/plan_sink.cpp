// Turns the interpreter's canonical commands into planner input for the motion component.
#include "plan_sink.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>
#include <variant>

#include "canon_geometry.hpp"
#include "interp/canon.hpp"
#include "joint_limits.hpp"
#include "kins_link.hpp"
#include "motion/geometry.hpp"
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
// change, waits, pauses, conditional moves) become action records after the motion before them
// has come to rest; M901 outputs ride on the next move's first record; encoder latches are
// refused; M801 messages ride on the next move like M901 outputs; M802's documented integer
// messages mask the limit switches or close the look-ahead; other commands this machine has
// nothing for are counted as ignored.
class Sink final : public PlanSink {
  public:
    Sink(motion::Planner& planner, const FeederConfig& cfg, ProgramFeeder& feeder)
        : planner_(planner),
          cfg_(cfg),
          feeder_(feeder),
          pos_mm_(planner.end_position()),
          joint_check_(cfg.machine.joints) {}

    void emit(const interp::Canon& c) override {
        std::visit([&](const auto& cmd) { handle(c.loc, cmd); }, c.cmd);
    }

    void restart_from(const motion::AxisArray& pos_mm) override {
        planner_.reset(pos_mm);
        pos_mm_ = pos_mm;
        off_path_ = true;
    }

    std::optional<motion::AxisArray> standing_off_path_mm() const override {
        if (!off_path_) return std::nullopt;
        return to_machine(pos_mm_);
    }

    motion::AxisArray to_machine(const motion::AxisArray& pos_mm) const override {
        motion::AxisArray out = pos_mm;
        for (int k = 0; k < motion::kAxes; ++k) out[k] += shift_mm_[k];
        return out;
    }

  private:
    void handle(const interp::SourceLoc& loc, const interp::canon::Traverse& t) {
        motion::PathSegment seg = base_segment(loc, t.end_mm, t.flags);
        seg.rapid = true;
        seg.rapid_mm_s = rapid_mm_s_;
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::FeedLine& f) {
        motion::PathSegment seg = base_segment(loc, f.end_mm, f.flags);
        seg.feed_mm_s = feed_mm_s_;
        wait_at_speed_if_due(loc);
        push(loc, seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Arc& a) {
        motion::PathSegment seg = base_segment(loc, a.end_mm, a.flags);
        motioncomp::set_arc_geometry(seg, a);
        seg.centre_mm[0] -= shift_mm_[seg.plane_first];  // into the planner's frame
        seg.centre_mm[1] -= shift_mm_[seg.plane_second];
        seg.feed_mm_s = feed_mm_s_;
        wait_at_speed_if_due(loc);
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
    // NcStudio's F in a G00 block (FEATURES G00-3): the rapids that follow go no faster than
    // this, nor faster than the axis limits allow; 0 = the axis limits alone.
    void handle(const interp::SourceLoc&, const interp::canon::SetRapidRate& r) {
        rapid_mm_s_ = r.rapid_mm_s;
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Dwell& d) {
        // The planner has no pause element: end the motion at rest, then queue a record that
        // stands still for the dwell time.
        if (d.seconds > 0) {
            const motion::PreparedSegment rec =
                dwell_record(pos_mm_, d.seconds, loc.line, cfg_.plan.max_rate);
            rest(&rec);
        } else {
            rest(nullptr);
        }
    }
    // A program that masked the limit switches and did not restore them: they count again at
    // its end, so the next program does not run with them masked.
    void handle(const interp::SourceLoc& loc, const interp::canon::ProgramEnd&) {
        if (limits_masked_) queue(loc, {motion::ActionKind::MaskLimits, false, 0, 0});
        limits_masked_ = false;
        rest(nullptr);
    }
    // G906 without a port: motion comes to rest before the program goes on.
    void handle(const interp::SourceLoc&, const interp::canon::Sync&) { rest(nullptr); }
    // LinuxCNC waits for spindle.0.at-speed at the start of the next feed move after a spindle
    // start or a speed change, not at the spindle command: rapids before it run at once.
    void handle(const interp::SourceLoc& loc, const interp::canon::SetSpindleSpeed& s) {
        if (spindle_running_) at_speed_due_ = true;
        queue(loc, {motion::ActionKind::SpindleSpeed, false, 0, s.rpm});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Spindle& s) {
        const int dir = s.dir == interp::SpindleDir::Cw    ? 1
                        : s.dir == interp::SpindleDir::Ccw ? -1
                                                           : 0;
        spindle_running_ = dir != 0;
        at_speed_due_ = spindle_running_;
        queue(loc, {motion::ActionKind::Spindle, false, dir, 0});
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::SpindleOrient& o) {
        spindle_running_ = at_speed_due_ = false;
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
    // M901 is synchronised with motion (LinuxCNC's M62/M63): the output changes when the path
    // reaches the start of the next move, blended or not, and nothing stops for it. Where the
    // motion comes to rest before another move (a dwell, an action, the program's end) it
    // changes there.
    void handle(const interp::SourceLoc& loc, const interp::canon::SetOutput& o) {
        check_port(loc, "M901", "output", "digital-out", o.port, cfg_.machine.digital_outputs);
        feeder_.sync_output(o.port, o.level, next_move_id_ + 1, loc.line);
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
        joint_check_.set_tool_offset(t.offset_mm[2]);
    }
    // M10 / M11 (V5.4; the 6th edition sends a warning instead): spindle.0.clamp.
    void handle(const interp::SourceLoc& loc, const interp::canon::SpindleClamp& c) {
        queue(loc, {motion::ActionKind::SpindleClamp, c.clamp, 0, 0});
    }
    // M801: shown when the path reaches the next move, without stopping it (like M901).
    void handle(const interp::SourceLoc& loc, const interp::canon::Message& m) {
        feeder_.sync_message(interp::Canon{loc, m}, next_move_id_ + 1);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Warning& w) {
        feeder_.post_text(interp::Canon{loc, w});
    }
    // M802 P: the integer messages S0 §3.10 documents for the machine (FEATURES IO-4, IO-5).
    void handle(const interp::SourceLoc& loc, const interp::canon::IntMessage& m) {
        switch (m.code) {
            case kMaskLimits:
            case kRestoreLimits:
                limits_masked_ = m.code == kMaskLimits;
                queue(loc, {motion::ActionKind::MaskLimits, limits_masked_, 0, 0});
                return;
            case kCloseBuffer:
            case kOpenBuffer:
                // No look-ahead past this point; while closed every block ends at rest before
                // the next one starts (push()).
                rest(nullptr);
                buffer_closed_ = m.code == kCloseBuffer;
                return;
            default:
                feeder_.count_ignored();
                if (!unhandled_codes_.insert(m.code).second) return;  // warned once per code
                feeder_.post_text(interp::Canon{
                    loc, interp::canon::Warning{fmt::format(
                             "M802 P{}: this machine has no handler for that integer message; "
                             "ignored",
                             m.code)}});
        }
    }
    // M902 H<a>: homing done; this point is the axis's machine coordinate `position_mm` from now
    // on. The motors stay where they are: the shift goes into the frame (see PlanSink).
    void handle(const interp::SourceLoc& loc, const interp::canon::HomeDone& h) {
        const int axis = h.axis;  // 0..3 = X Y Z A, the planner's first four axes
        if (axis < 0 || axis >= motion::kAxes || !cfg_.axis_present[axis])
            throw interp::Error(
                loc, fmt::format("M902: axis {} is not on this machine (coordinates={})",
                                 axis >= 0 && axis < motion::kAxes ? kAxisLetters[axis] : '?',
                                 cfg_.coordinates));
        shift_mm_[axis] = h.position_mm - pos_mm_[axis];
        queue(loc, {motion::ActionKind::HomeDone, false, axis, shift_mm_[axis]});
    }
    // Informational: end points already include offsets, units and plane are per move.
    void handle(const interp::SourceLoc&, const interp::canon::Offsets&) {}
    void handle(const interp::SourceLoc&, const interp::canon::Units&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SelectPlane&) {}
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedMode&) {}
    // G904: the axes move on their own (motion::ProbeJog) from where the motion before came to
    // rest; nothing after it can be planned before the machine has told where it stopped.
    void handle(const interp::SourceLoc& loc, const interp::canon::ConditionalMove& cm) {
        motion::PreparedSegment rec = motion::action_record(
            pos_mm_, {motion::ActionKind::ConditionalMove, cm.flags.force_full_override, 0, 0},
            loc.line);
        for (int k = 0; k < motion::kProbeAxes; ++k) {
            const auto& w = cm.axes[k];
            if (!w) continue;
            check_port(loc, "G904", "input", "digital-in", w->port, cfg_.machine.digital_inputs);
            const int axis = k;  // the interpreter's X Y Z are the planner's first three axes
            if (!cfg_.axis_present[axis])
                throw interp::Error(
                    loc, fmt::format("G904: axis {} moves but the machine has only coordinates={}",
                                     kAxisLetters[axis], cfg_.coordinates));
            motion::ProbeAxis& p = rec.probe[axis];
            p.input = w->port;
            p.level = w->level;
            p.speed_mm_s = w->speed_mm_s;
            // Never past the soft limit in the direction of travel (LinuxCNC's probe moves end
            // inside the limits too); the maximum travel, if given, may stop it sooner.
            const double here_mm = pos_mm_[axis] + shift_mm_[axis];  // machine coordinate
            const double to_limit = w->speed_mm_s > 0 ? cfg_.machine.max_limit_mm[axis] - here_mm
                                                      : here_mm - cfg_.machine.min_limit_mm[axis];
            p.travel_mm = std::max(0.0, std::min(to_limit, w->max_travel_mm.value_or(to_limit)));
        }
        keep_probe_inside_joint_limits(rec);
        rest(&rec);
        feeder_.await_probe(loc, cm);
    }
    // Nor past a joint soft limit: each axis may stop anywhere in its travel, so the travels
    // are shortened together until every corner of the box they span maps inside the joint
    // limits (a CoreXY probing X and Y at once can reach X + Y at the far corner).
    void keep_probe_inside_joint_limits(motion::PreparedSegment& rec) {
        motion::AxisArray span{};
        for (int k = 0; k < motion::kProbeAxes; ++k) {
            const motion::ProbeAxis& p = rec.probe[k];
            if (p.input >= 0 && p.speed_mm_s != 0)
                span[k] = p.speed_mm_s > 0 ? p.travel_mm : -p.travel_mm;
        }
        const double f = joint_check_.box_scale(pos_mm_, span);
        for (int k = 0; k < motion::kProbeAxes; ++k) rec.probe[k].travel_mm *= f;
    }

    // G916 / G918 / G919 ask the drives to latch their encoders on an input; this machine has
    // no latch path from its drives, so a program that relies on one is refused.
    void handle(const interp::SourceLoc& loc, const interp::canon::LatchConfig&) {
        refuse_latch(loc, "G916");
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::LatchClear&) {
        refuse_latch(loc, "G918");
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::LatchStopDistance&) {
        refuse_latch(loc, "G919");
    }
    template <class Other>
    void handle(const interp::SourceLoc&, const Other&) {
        feeder_.count_ignored();
    }

    motion::PathSegment base_segment(const interp::SourceLoc& loc, const interp::AxisVec& end,
                                     const interp::canon::MoveFlags& flags) {
        motion::PathSegment seg;
        seg.end_mm = to_axes(end);
        for (int k = 0; k < motion::kAxes; ++k) seg.end_mm[k] -= shift_mm_[k];
        seg.tolerance_mm = tolerance_mm_;
        seg.exact_stop = flags.exact_stop;  // G09
        seg.line = loc.line;
        seg.move_id = ++next_move_id_;
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k] && std::fabs(seg.end_mm[k] - pos_mm_[k]) > 1e-9)
                throw interp::Error(
                    loc, fmt::format("axis {} moves but the machine has only coordinates={}",
                                     kAxisLetters[k], cfg_.coordinates));
        }
        return seg;
    }

    // The motion so far ends at rest, then the action's record stands in the queue.
    void queue(const interp::SourceLoc& loc, const motion::Action& action) {
        const motion::PreparedSegment rec = motion::action_record(pos_mm_, action, loc.line);
        rest(&rec);
    }

    // The motion so far ends at rest; `extra` (an action or a dwell), if any, follows it.
    void rest(const motion::PreparedSegment* extra) {
        planner_.finish();
        feeder_.collect_at_rest(pos_mm_, extra);
    }

    void wait_at_speed_if_due(const interp::SourceLoc& loc) {
        if (!at_speed_due_) return;
        at_speed_due_ = false;
        queue(loc, {motion::ActionKind::SpindleAtSpeed, false, 0, 0});
    }

    [[noreturn]] static void refuse_latch(const interp::SourceLoc& loc, const char* code) {
        throw interp::Error(
            loc, fmt::format("{}: encoder latches are not supported on this machine (the motion "
                             "component has no latch input from its drives)",
                             code));
    }

    static void check_port(const interp::SourceLoc& loc, const char* code, const char* what,
                           const char* pin, int port, int count) {
        if (port >= 0 && port < count) return;
        throw interp::Error(
            loc, fmt::format("{}: {} {} does not exist: the machine has motion.{}-00 to {:02} "
                             "(num_dio={})",
                             code, what, port, pin, count - 1, count));
    }

    // LinuxCNC refuses a move whose path leaves the soft limits before it starts; so does this.
    void check_soft_limits(const interp::SourceLoc& loc, const motion::PathSegment& seg) const {
        const Extent reach = segment_reach(pos_mm_, seg);
        constexpr double kSlack_mm = 1e-9;  // rounding of arc extremes computed from angles
        for (int k = 0; k < motion::kAxes; ++k) {
            if (!cfg_.axis_present[k]) continue;
            // The limits are machine coordinates; the reach is in the planner's frame.
            const double lo = cfg_.machine.min_limit_mm[k] - shift_mm_[k];
            const double hi = cfg_.machine.max_limit_mm[k] - shift_mm_[k];
            const bool low = reach.lo_mm[k] < lo - kSlack_mm;
            if (!low && reach.hi_mm[k] <= hi + kSlack_mm) continue;
            throw interp::Error(
                loc,
                fmt::format("the move takes {} to {} mm, which exceeds the soft limit "
                            "axis.{}.{}-limit = {} mm",
                            kAxisLetters[k],
                            interp::fmt_num((low ? reach.lo_mm[k] : reach.hi_mm[k]) + shift_mm_[k]),
                            kLowerAxes[k], low ? "min" : "max",
                            interp::fmt_num((low ? lo : hi) + shift_mm_[k])));
        }
    }

    // The joints along the move's path (joint_limits.hpp), before the planner has it: a move
    // that would take a motor past its travel is refused at its line, and the machine comes to
    // rest where the move before ended.
    void check_joint_limits(const interp::SourceLoc& loc, const motion::Element& path) {
        const std::optional<JointViolation> v = joint_check_.check(path);
        if (!v) return;
        const JointLimitConfig& jc = joint_check_.config();
        const auto joint = static_cast<std::size_t>(v->joint);
        // A joint that drives A, B or C turns (degrees).
        const int axis = jc.kins->kins().joint_axes()[joint];
        const char* unit = axis >= 3 && axis <= 5 ? "deg" : "mm";
        const motion::AxisArray at = to_machine(v->at_mm);
        std::string where;
        for (int k = 0; k < motion::kAxes; ++k)
            if (cfg_.axis_present[k])
                where += fmt::format("{}{}{}", where.empty() ? "" : " ", kAxisLetters[k],
                                     interp::fmt_num(at[k]));
        throw interp::Error(
            loc,
            fmt::format(
                "joint {} would move to {} {} (axis position {}), beyond its soft limit "
                "[{:g}, {:g}] {} ({}.{}.{}-limit); the move is refused before it starts",
                v->joint,
                position_text(v->position, v->above ? jc.max_limit[joint] : jc.min_limit[joint]),
                unit, where, jc.min_limit[joint], jc.max_limit[joint], unit, jc.pin_stem, v->joint,
                v->above ? "max" : "min"));
    }

    // Four decimals, or as many as it takes to show the position beyond `limit`.
    static std::string position_text(double pos, double limit) {
        std::string text = interp::fmt_num(pos);
        const double shown = std::strtod(text.c_str(), nullptr);
        if ((pos > limit) != (shown > limit) || (pos < limit) != (shown < limit))
            text = fmt::format("{:.12g}", pos);
        return text;
    }

    // PlanError says "line N: reason"; the user needs the file too.
    [[noreturn]] static void rethrow_with_file(const interp::SourceLoc& loc,
                                               const motion::PlanError& e) {
        std::string reason = e.what();
        const auto colon = reason.find(": ");
        if (colon != std::string::npos) reason.erase(0, colon + 2);
        throw interp::Error(loc, reason);
    }

    // Under a kinematics the planner has no joint map of, the move goes no faster than keeps
    // every joint within joint.N.max-velocity (joint_limits.hpp, "Joint rates"): a feed is
    // lowered to that speed, a rapid gets it as its rapid rate.
    static motion::PathSegment with_speed_cap(const motion::PathSegment& seg, double cap_mm_s) {
        motion::PathSegment out = seg;
        if (!(cap_mm_s < std::numeric_limits<double>::infinity())) return out;
        if (seg.rapid)
            out.rapid_mm_s = seg.rapid_mm_s > 0 ? std::min(seg.rapid_mm_s, cap_mm_s) : cap_mm_s;
        else
            out.feed_mm_s = std::min(seg.feed_mm_s, cap_mm_s);
        return out;
    }

    // The highest path speed the axes' velocity limits allow anywhere on `path`.
    double axes_speed_mm_s(const motion::Element& path) const {
        const motion::ElementBounds b = motion::bounds(path);
        double v = std::numeric_limits<double>::infinity();
        for (int k = 0; k < motion::kAxes; ++k)
            if (b.g1[k] > 0) v = std::min(v, cfg_.plan.limits.vel_mm_s[k] / b.g1[k]);
        return v;
    }

    void push(const interp::SourceLoc& loc, const motion::PathSegment& programmed) {
        check_soft_limits(loc, programmed);
        try {
            motion::PathSegment seg = programmed;
            if (joint_check_.config().kins) {
                const motion::Element path = seg.kind == motion::SegmentKind::Arc
                                                 ? motion::make_arc(pos_mm_, seg)
                                                 : motion::make_line(pos_mm_, seg.end_mm);
                check_joint_limits(loc, path);
                if (!joint_check_.config().max_velocity.empty())  // a nonlinear kinematics
                    seg = with_speed_cap(seg,
                                         joint_check_.speed_cap_mm_s(path, axes_speed_mm_s(path)));
            }
            // The look-ahead closed (M802 P196609): the block before ends at rest first.
            if (buffer_closed_ && seg.line != last_move_line_) rest(nullptr);
            last_move_line_ = seg.line;
            planner_.push(seg);
        } catch (const motion::PlanError& e) {
            rethrow_with_file(loc, e);
        }
        pos_mm_ = programmed.end_mm;
        off_path_ = false;
        feeder_.collect();
    }

    motion::Planner& planner_;
    const FeederConfig& cfg_;
    ProgramFeeder& feeder_;
    motion::AxisArray pos_mm_;
    bool off_path_ = false;  // pos_mm_ is where a conditional move stopped, not a move's end
    double feed_mm_s_ = 0;
    double rapid_mm_s_ = 0;  // programmed rapid rate; 0 = as fast as the axes allow
    double tolerance_mm_ = cfg_.blend_tolerance_mm;  // the G61/G64 mode in force
    std::uint32_t next_move_id_ = 0;                 // move_id of the last segment made
    bool spindle_running_ = false;                   // as the program has commanded it
    bool at_speed_due_ = false;     // the next feed move waits for spindle.0.at-speed
    motion::AxisArray shift_mm_{};  // machine coordinate minus planner frame, per axis (M902)
    bool buffer_closed_ = false;    // between M802 P196609 and P196608
    bool limits_masked_ = false;    // between M802 P131072 and P131073
    std::int32_t last_move_line_ = -1;
    std::set<std::int64_t> unhandled_codes_;  // M802 codes already warned about
    JointLimitCheck joint_check_;

    // M802 P values (S0 §3.10; FEATURES M802-1).
    static constexpr std::int64_t kMaskLimits = 0x20000;     // 131072
    static constexpr std::int64_t kRestoreLimits = 0x20001;  // 131073
    static constexpr std::int64_t kCloseBuffer = 0x30001;    // 196609
    static constexpr std::int64_t kOpenBuffer = 0x30000;     // 196608
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

std::unique_ptr<PlanSink> make_plan_sink(motion::Planner& planner, const FeederConfig& cfg,
                                         ProgramFeeder& feeder) {
    return std::make_unique<Sink>(planner, cfg, feeder);
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
