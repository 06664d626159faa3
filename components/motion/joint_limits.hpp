// Joint soft limits at plan time: the path of a programmed move, mapped through the machine's
// kinematics, against joint.N.min-limit / max-limit, before the move is given to the planner.
// The servo function checks every joint command again (motion.cpp, the last line of defence);
// this check is what turns "a program the machine cannot run" into an error naming its line
// before the machine moves there. Runs on the feeder thread, with a kinematics of its own.
//
// How the path is sampled (the bound). A joint along a move is a smooth function f(s) of the
// path length. The move is cut into pieces of at most 90 degrees of arc and 10 degrees of
// rotary-axis travel (A, B, C), so that on a piece f is close to a parabola; each piece is then
// halved where needed. On an interval with end values f0, f1 and middle value fm, the deviation
// d = fm - (f0 + f1) / 2 measures its curvature: a parabola exceeds its largest sample by at
// most |d|, and the check allows for 2 |d|. An arc through a kinematics linear in the axes
// gives joints f = a cos(t - phi) + b t + c, which on a 90-degree piece exceed their samples by
// at most 0.37 |d| (computed over phi and b); a rotation of 10 degrees or less is as close to
// its parabola. An interval whose samples plus 2 |d| stay within the limits is cleared; one
// that does not is halved, until a sample lies beyond a limit (refused) or |d| < 1e-6 mm (or
// degree), when it is cleared with its samples inside: a joint may then pass its limit between
// samples by at most 2e-6. A line under a kinematics that is linear in the axes (trivial,
// gantry, CoreXY, and TRT with its rotary axes still) has d = 0: its end points decide exactly,
// from two inverse calls (the start's joints are the last move's end's).
//
// Corner blends are not sampled: they lie inside the convex hull of their corner, which a
// linear kinematics maps inside the joint limits when both moves are. Under a kinematics with
// rotary axes a blend within the tolerance of a move that rides on a joint limit can pass it
// by about the tolerance; the servo check stops the machine then.
//
// A machine standing outside a joint limit (after a reset) may move back in, as for the axis
// limits: points on the way may be as far out as the start, the end must be inside.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "motion/geometry.hpp"
#include "motion/types.hpp"

namespace motioncomp {

class PlanningKinematics;

// The joint side of what the sink checks a program against, from motion's params at start().
struct JointLimitConfig {
    std::shared_ptr<PlanningKinematics> kins;  // null: joints are not checked at plan time
    std::vector<double> min_limit, max_limit;  // per joint, in its axis's unit (mm or degrees)
    std::string pin_stem = "joint";            // for messages: <stem>.N.max-limit
};

// The point of a move's path where a joint would be farthest beyond its limit (beyond what the
// move is allowed: see "A machine standing outside" above).
struct JointViolation {
    int joint = 0;
    double position = 0;        // the joint's position there
    bool above = false;         // past max-limit (else below min-limit)
    motion::AxisArray at_mm{};  // the axes there, in the planner's frame
    double s_mm = 0;            // there along the path
};

class JointLimitCheck {
  public:
    // LinuxCNC's limit on joints (EMCMOT_MAX_JOINTS).
    static constexpr std::size_t kMaxJoints = 16;

    // Throws std::invalid_argument for a kinematics with more than kMaxJoints joints or limit
    // lists of another length.
    explicit JointLimitCheck(JointLimitConfig cfg);

    // A point of the path of `e` (a programmed line or arc, in the planner's frame) beyond a
    // joint limit, or none. The start of the path is where the machine stands: it is not
    // refused, only measured (see "A machine standing outside" above).
    std::optional<JointViolation> check(const motion::Element& e);
    // The largest f in [0, 1] for which every corner of the box from `from_mm` to
    // from_mm + f * span_mm keeps the joints within their limits (or no farther out than at
    // `from_mm`): how much of its travel a move whose axes each stop anywhere in their range
    // (G904) may be given. Exact for a kinematics affine in the axes that
    // move, as every one here is with its rotary axes still: to 1e-12 of the travel kept.
    // 1 without a kinematics.
    double box_scale(const motion::AxisArray& from_mm, const motion::AxisArray& span_mm);
    // The tool length offset the moves from now on run with (G43/G49).
    void set_tool_offset(double tool_offset_mm) noexcept;
    const JointLimitConfig& config() const noexcept { return cfg_; }

  private:
    using Joints = std::array<double, kMaxJoints>;
    bool corners_inside(const motion::AxisArray& from_mm, const motion::AxisArray& span_mm,
                        double f) const noexcept;
    void joints_at(const motion::Element& e, double s_mm, Joints& out) const noexcept;
    std::optional<JointViolation> beyond(const motion::Element& e, double s_mm, const Joints& j,
                                         bool at_end) const noexcept;
    struct Farthest {
        double s_mm, excess;
    };
    JointViolation farthest(const motion::Element& e, int pieces,
                            const JointViolation& v) const noexcept;
    template <class Excess>
    void maximise(const motion::Element& e, Excess& excess, double s0, double g0, double s1,
                  double g1, int depth, Farthest& f) const noexcept;
    std::optional<JointViolation> refine(const motion::Element& e, double s0, const Joints& j0,
                                         double s1, const Joints& j1, int depth) const noexcept;

    JointLimitConfig cfg_;
    std::size_t joints_ = 0;
    // How far the move's start lies beyond each limit (0 inside): what its points may reach.
    Joints allow_above_{}, allow_below_{};
    // The end of the last move cleared and its joints (with the tool offset then in force).
    bool last_end_known_ = false;
    motion::AxisArray last_end_mm_{};
    Joints last_end_joints_{};
};

}  // namespace motioncomp
