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
//
// Joint rates at plan time (speed_cap_mm_s). Under a kinematics the planner has no joint map of (a
// tilting table's joints depend on the angles) the planner limits the axes only. A joint moves at
// dq/dt = g(s) v, g = dq/ds = J p', v = ds/dt the path speed (s the planner's path length: rotary
// degrees count as mm), and accelerates at g dv/dt + (J p'' + h) v^2, where h = D2q[p', p'] is the
// curvature the kinematics adds to the path's own (a C rotation turns a straight line in C into a
// circle of the motors X and Y). So the move's speed is capped at min over joints of max_velocity /
// max|g| (a feed is lowered to it, a rapid gets it as its rapid rate) and at
// sqrt(kCurvatureAccShare max_acceleration / max|h|), both divided by the override the sampler may
// apply on top (max_rate), unless the axes' own velocity limits keep the path slower than that
// anyway (the sampler's rate caps keep the axes within them at any override, so a joint that
// mirrors an axis costs no speed). g and h come from central differences of the inverse kinematics
// along the path's tangent (a 1e-2 mm or degree step: truncation about 2e-5 |q'''| in g, rounding
// about 1e-9 in h; a step of 1e-3 left h too noisy to stop halving) at the ends and middle of the
// same pieces as the soft limit check (90 degrees of arc, 10 degrees of rotary travel); on such a
// piece g and h are as close to parabolas as the joints are, so the same allowance bounds them: max
// |g| <= the largest sample + 2 |d|, d the midpoint deviation. A piece is halved (at most 10 times)
// until 2 |d| is within 0.1 % of its bound, or of the joint's largest rate at the piece ends
// (+1e-6): the cap is then at most about 0.1 % below the exact one. A cap within that 0.1 % of the
// speed the axes allow is not applied (a joint that mirrors an axis along a curve would otherwise
// slow the move by the allowance): such a joint may reach 1.001 times its max_velocity, the servo
// check's slack. Not covered, left to the servo function's check (reported at stop): the
// acceleration terms g dv/dt and J p'' v^2, which the planner keeps within the axes' limits, not
// the joints' (on a tilted table an axis's acceleration lands partly on another motor), so the half
// of max_acceleration h leaves is not a guarantee for them; corner blends, which are not sampled (a
// blend's tangent lies between the two moves' tangents at a point within the tolerance of the
// corner, and it runs no faster than the slower move, so its joint speeds are the moves' there to
// within the tolerance).
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
    // Per joint, joint.N.max-velocity / max-acceleration (0 = unlimited), for a kinematics the
    // planner has no joint map of (speed_cap_mm_s()); empty: the joints' rates are not planned
    // here (a linear kinematics, whose joints the planner limits itself).
    std::vector<double> max_velocity, max_acceleration;
    double max_rate = 1;  // the highest override the sampler may apply (PlannerConfig::max_rate)
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
    // The highest path speed (mm/s of the planner's path length s; see "Joint rates" above) at
    // which e keeps every joint within its max_velocity, and its curvature term within
    // kCurvatureAccShare of max_acceleration, at any override up to max_rate. e: a programmed
    // line or arc; axes_speed_mm_s: the highest path speed the axes' own velocity limits allow
    // on it, which the planner and the sampler keep at any override. +infinity when no joint
    // rate is planned here or the axes' speed already keeps the joints within their limits.
    double speed_cap_mm_s(const motion::Element& e, double axes_speed_mm_s) const noexcept;
    // The share of a joint's max_acceleration its curvature term |d2q/ds2| v^2 may take.
    static constexpr double kCurvatureAccShare = 0.5;
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
    struct Rates {
        Joints g, h;  // dq/ds and d2q/ds2
    };
    void rates_at(const motion::Element& e, double s_mm, Rates& out) const noexcept;
    void bound_rates(const motion::Element& e, double s0, const Rates& r0, double s1,
                     const Rates& r1, int depth, const Rates& scale, Joints& g_max,
                     Joints& h_max) const noexcept;
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
